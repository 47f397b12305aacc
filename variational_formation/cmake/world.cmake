# The MuJoCo world (doc/robots.md, "The MuJoCo world"): model building and stepping without ROS
# (variational_formation_world, over the core and libmujoco), the mujoco_world node, the
# world_step_response tool and their tests. MuJoCo is required: Debian's libmujoco-dev.
find_package(mujoco QUIET)
# Debian's mujoco::mujoco target names /usr/include/libqhull_r/ among its include folders, which
# only libqhull-dev provides (and MuJoCo's headers never include): the library and its header
# folder are taken on their own instead of through the target.
find_path(VF_MUJOCO_INCLUDE_DIR mujoco/mujoco.h)
find_library(VF_MUJOCO_LIBRARY mujoco)
if(NOT mujoco_FOUND OR NOT VF_MUJOCO_INCLUDE_DIR OR NOT VF_MUJOCO_LIBRARY)
  message(FATAL_ERROR "MuJoCo not found (find_package(mujoco), mujoco/mujoco.h, libmujoco): the "
    "mujoco_world node needs it. Install Debian's libmujoco-dev (apt-get install libmujoco-dev; "
    "scripts/test.sh installs it from package.xml's key libmujoco-dev).")
endif()

# Contacts as both worlds count them (ContactLog; BodyContacts for robot_sim), without MuJoCo.
add_library(variational_formation_contacts src/world/body_contacts.cpp src/world/contact_log.cpp)
target_link_libraries(variational_formation_contacts PUBLIC ${variational_formation_core_LIBRARIES})
target_compile_options(variational_formation_contacts PRIVATE ${VF_FLAGS})
set_target_properties(variational_formation_contacts PROPERTIES POSITION_INDEPENDENT_CODE ON)
install(TARGETS variational_formation_contacts
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

add_library(variational_formation_world src/world/mjcf_model.cpp
  src/world/mujoco_world.cpp src/world/step_response.cpp src/world/wheel_odometry.cpp src/world/world_settings.cpp)
# Private: the world's headers declare MuJoCo's types without including mujoco.h.
target_include_directories(variational_formation_world SYSTEM PRIVATE ${VF_MUJOCO_INCLUDE_DIR})
target_link_libraries(variational_formation_world PUBLIC variational_formation_contacts PRIVATE ${VF_MUJOCO_LIBRARY})
target_compile_options(variational_formation_world PRIVATE ${VF_FLAGS})
set_target_properties(variational_formation_world PROPERTIES POSITION_INDEPENDENT_CODE ON)
install(TARGETS variational_formation_world
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

add_executable(world_step_response src/tools/world_step_response_main.cpp)
target_link_libraries(world_step_response variational_formation_world variational_formation_tools)
target_compile_options(world_step_response PRIVATE ${VF_FLAGS})
install(TARGETS world_step_response RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

add_executable(mujoco_world src/ros/mujoco_world_main.cpp src/ros/mujoco_world_node.cpp src/ros/world_markers.cpp)
target_link_libraries(mujoco_world variational_formation_ros variational_formation_world ${catkin_LIBRARIES})
target_compile_options(mujoco_world PRIVATE ${VF_FLAGS})
add_dependencies(mujoco_world ${catkin_EXPORTED_TARGETS})
install(TARGETS mujoco_world RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  foreach(name mjcf_model mujoco_world)
    catkin_add_gtest(test_${name} test/world/test_${name}.cpp)
    # The model test loads the MJCF with MuJoCo itself.
    target_include_directories(test_${name} SYSTEM PRIVATE ${VF_MUJOCO_INCLUDE_DIR})
    target_link_libraries(test_${name} variational_formation_world ${VF_MUJOCO_LIBRARY} gtest_main)
    target_compile_options(test_${name} PRIVATE ${VF_FLAGS})
    target_compile_definitions(test_${name} PRIVATE VF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  endforeach()
  # The world's rviz markers, a function of the world (no master).
  catkin_add_gtest(test_world_markers test/world/test_world_markers.cpp src/ros/world_markers.cpp)
  target_link_libraries(test_world_markers variational_formation_ros variational_formation_world gtest_main)
  target_compile_options(test_world_markers PRIVATE ${VF_FLAGS})
endif()

# Its real-time factor against the robot count, for the checkout only (like benchmark_roa).
add_executable(benchmark_world benchmark/benchmark_world.cpp)
target_link_libraries(benchmark_world variational_formation_world)
target_compile_options(benchmark_world PRIVATE ${VF_FLAGS})
