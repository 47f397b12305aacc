# ROS-free command-line tools over the core. They land in the package's lib folder, so
# `rosrun variational_formation simulate` finds them.
add_library(variational_formation_tools
  src/tools/arguments.cpp
  src/tools/assign_slots_cli.cpp
  src/tools/scenario_info_cli.cpp
  src/tools/simulate_cli.cpp
)
target_link_libraries(variational_formation_tools PUBLIC ${variational_formation_core_LIBRARIES})
# Scenario names (--scenario hexagon) are looked up without ROS too, beside the running program
# (tools/scenario_path.hpp): nothing about the build's folders is compiled in.
target_sources(variational_formation_tools PRIVATE src/tools/scenario_path.cpp)
target_compile_options(variational_formation_tools PRIVATE ${VF_FLAGS})

vf_add_tool(simulate src/tools/simulate_main.cpp)
install(TARGETS variational_formation_tools
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

vf_add_tool(scenario_info src/tools/scenario_info_main.cpp)

# assign_slots: which robot takes which desired position, from their current positions.
vf_add_tool(assign_slots src/tools/assign_slots_main.cpp)

# make_scenario: generated rigid formations (grids, rings, lattices, Henneberg) of any size.
target_sources(variational_formation_tools PRIVATE
  src/tools/make_scenario_cli.cpp
  src/tools/deployment.cpp
)
vf_add_tool(make_scenario src/tools/make_scenario_main.cpp)
vf_add_gtest(test_make_scenario test/tools/test_make_scenario.cpp variational_formation_tools)
vf_add_gtest(test_scenario_path test/tools/test_scenario_path.cpp variational_formation_tools)
# scenario_info's rigidity lines, make_scenario --graph and assign_slots.
vf_add_gtest(test_shape_tools test/tools/test_shape_tools.cpp variational_formation_tools)
