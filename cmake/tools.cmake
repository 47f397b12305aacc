# ROS-free command-line tools over the core. They land in the package's lib folder, so
# `rosrun variational_formation simulate` finds them.
add_library(variational_formation_tools
  src/tools/arguments.cpp
  src/tools/assign_slots_cli.cpp
  src/tools/scenario_info_cli.cpp
  src/tools/simulate_cli.cpp
)
target_link_libraries(variational_formation_tools PUBLIC variational_formation_core)
# Scenario names (--scenario hexagon) are looked up without ROS too, beside the running program
# (tools/scenario_path.hpp): nothing about the build's folders is compiled in.
target_sources(variational_formation_tools PRIVATE src/tools/scenario_path.cpp)
target_compile_options(variational_formation_tools PRIVATE ${VF_FLAGS})

add_executable(simulate src/tools/simulate_main.cpp)
target_link_libraries(simulate variational_formation_tools)
target_compile_options(simulate PRIVATE ${VF_FLAGS})
install(TARGETS simulate variational_formation_tools
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION}
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

add_executable(scenario_info src/tools/scenario_info_main.cpp)
target_link_libraries(scenario_info variational_formation_tools)
target_compile_options(scenario_info PRIVATE ${VF_FLAGS})
install(TARGETS scenario_info RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# assign_slots: which robot takes which desired position, from their current positions.
add_executable(assign_slots src/tools/assign_slots_main.cpp)
target_link_libraries(assign_slots variational_formation_tools)
target_compile_options(assign_slots PRIVATE ${VF_FLAGS})
install(TARGETS assign_slots RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# make_scenario: generated rigid formations (grids, rings, lattices, Henneberg) of any size.
target_sources(variational_formation_tools PRIVATE
  src/tools/formation_generators.cpp
  src/tools/globally_rigid_graph.cpp
  src/tools/make_scenario_cli.cpp
)
add_executable(make_scenario src/tools/make_scenario_main.cpp)
target_link_libraries(make_scenario variational_formation_tools)
target_compile_options(make_scenario PRIVATE ${VF_FLAGS})
install(TARGETS make_scenario RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_make_scenario test/tools/test_make_scenario.cpp)
  target_link_libraries(test_make_scenario variational_formation_tools gtest_main)
  target_compile_options(test_make_scenario PRIVATE ${VF_FLAGS})
  target_compile_definitions(test_make_scenario PRIVATE VF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  # scenario_info's rigidity lines, make_scenario --graph and assign_slots.
  catkin_add_gtest(test_shape_tools test/tools/test_shape_tools.cpp)
  target_link_libraries(test_shape_tools variational_formation_tools gtest_main)
  target_compile_options(test_shape_tools PRIVATE ${VF_FLAGS})
  target_compile_definitions(test_shape_tools PRIVATE VF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  catkin_add_gtest(test_scenario_path test/tools/test_scenario_path.cpp)
  target_link_libraries(test_scenario_path variational_formation_tools gtest_main)
  target_compile_options(test_scenario_path PRIVATE ${VF_FLAGS})
  target_compile_definitions(test_scenario_path PRIVATE VF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()
