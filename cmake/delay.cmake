# Delayed and lossy model, delay margin (predicted and simulated), the `delay_margin` CLI and
# their tests. Included after tools.cmake.
target_sources(variational_formation_core PRIVATE
  src/core/parallel.cpp
  src/core/delayed_integrator.cpp
  src/core/delay_margin.cpp
  src/core/delay_campaign.cpp
  src/core/robot_mode.cpp
  src/core/robot_link.cpp)
target_sources(variational_formation_tools PRIVATE
  src/tools/progress.cpp
  src/tools/delay_margin_cli.cpp)

add_executable(delay_margin src/tools/delay_margin_main.cpp)
target_link_libraries(delay_margin variational_formation_tools)
target_compile_options(delay_margin PRIVATE ${VF_FLAGS})
install(TARGETS delay_margin RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_delayed_integrator test/core/test_delayed_integrator.cpp)
  target_link_libraries(test_delayed_integrator variational_formation_core gtest_main)
  catkin_add_gtest(test_robot_mode test/core/test_robot_mode.cpp)
  target_link_libraries(test_robot_mode variational_formation_core gtest_main)
  catkin_add_gtest(test_robot_link test/core/test_robot_link.cpp)
  target_link_libraries(test_robot_link variational_formation_core gtest_main)
  catkin_add_gtest(test_delay_margin test/tools/test_delay_margin.cpp)
  target_link_libraries(test_delay_margin variational_formation_tools gtest_main)
  foreach(t test_delayed_integrator test_robot_mode test_robot_link test_delay_margin)
    target_compile_options(${t} PRIVATE ${VF_FLAGS})
    target_compile_definitions(${t} PRIVATE VF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  endforeach()
endif()
