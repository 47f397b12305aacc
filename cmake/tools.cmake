# ROS-free command-line tools over the core. They land in the package's lib folder, so
# `rosrun variational_formation simulate` finds them.
add_library(variational_formation_tools
  src/tools/arguments.cpp
  src/tools/simulate_cli.cpp
)
target_link_libraries(variational_formation_tools PUBLIC variational_formation_core)
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
