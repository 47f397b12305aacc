# Delayed and lossy model, delay margin (predicted and simulated), the `delay_margin` CLI and
# their tests. Included after tools.cmake.
target_sources(variational_formation_tools PRIVATE
  src/tools/progress.cpp
  src/tools/delay_margin_cli.cpp)

vf_add_tool(delay_margin src/tools/delay_margin_main.cpp)
foreach(name delayed_integrator robot_mode robot_link)
  vf_add_gtest(test_${name} test/core/test_${name}.cpp "${variational_formation_core_LIBRARIES}")
endforeach()
vf_add_gtest(test_delay_margin test/tools/test_delay_margin.cpp variational_formation_tools)
