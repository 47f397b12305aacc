# The ROS-free core: Eigen and yaml-cpp only. catkin's include path is not given to this
# target, but on Debian the ROS headers live in /usr/include beside Eigen's, so that alone
# cannot stop a ROS include from compiling: test/core/test_layers.cpp is the guard.
# In the order of the concepts (the formation model, the integrators on it, what uses them),
# not alphabetical.
#catkin_lint: ignore_once unsorted_list
add_library(variational_formation_core
  src/core/formation.cpp
  src/core/force_model.cpp
  src/core/variational_update.cpp
  src/core/integrator.cpp
  src/core/variational_integrator.cpp
  src/core/explicit_integrators.cpp
  src/core/metrics.cpp
  src/core/stability.cpp
  src/core/sparse_spectrum.cpp
  src/core/scenario.cpp
  src/core/validation.cpp
  src/core/simulation.cpp
  src/core/lockstep_agent.cpp
  src/core/monitor.cpp
  src/core/number_checks.cpp
  src/core/link_faults.cpp
  src/core/agent_neighbourhood.cpp
  src/core/timed_agent.cpp
  src/core/point_robot.cpp
  src/core/hand_point.cpp
  src/core/unicycle_robot.cpp
  src/core/record_ledger.cpp
  src/core/manoeuvre_command.cpp
  src/core/motion_parameters.cpp
  src/core/manoeuvre.cpp
  src/core/manoeuvre_integrator.cpp
  src/core/tracking.cpp
  src/core/run_outcome.cpp
  src/core/rigidity.cpp
  src/core/procrustes.cpp
  src/core/hungarian.cpp
  src/core/slot_assignment.cpp
  src/core/shape_outcome.cpp
  src/core/goal_steering.cpp
  src/core/spatial_grid.cpp
  src/core/safety_filter.cpp
  src/core/safety_validation.cpp
  src/core/safety_stage.cpp
  src/core/timed_safety.cpp
  src/core/safety_watch.cpp
  src/core/sensing_board.cpp
  src/core/blocked_detector.cpp
  src/core/run_tracker.cpp
  src/core/protocol/recovery.cpp
  src/core/protocol/command_desk.cpp
)
target_include_directories(variational_formation_core PUBLIC
  $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>)
target_include_directories(variational_formation_core SYSTEM PUBLIC ${EIGEN3_INCLUDE_DIR})
target_link_libraries(variational_formation_core PUBLIC yaml-cpp)
target_compile_options(variational_formation_core PRIVATE ${VF_FLAGS})
set_target_properties(variational_formation_core PROPERTIES POSITION_INDEPENDENT_CODE ON)
install(TARGETS variational_formation_core
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
