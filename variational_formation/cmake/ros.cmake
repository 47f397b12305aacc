# The ROS layer: thin nodes over the core, plus rostests.
add_library(variational_formation_ros
  src/ros/agent_commands.cpp
  src/ros/agent_node.cpp
  src/ros/agent_recovery.cpp
  src/ros/agent_sensing.cpp
  src/ros/bag_writer.cpp
  src/ros/formation_subscriptions.cpp
  src/ros/frame_broadcaster.cpp
  src/ros/frame_gate.cpp
  src/ros/frames.cpp
  src/ros/liveness.cpp
  src/ros/local_states.cpp
  src/ros/markers.cpp
  src/ros/monitor_node.cpp
  src/ros/output_files.cpp
  src/ros/participant_names.cpp
  src/ros/progress_message.cpp
  src/ros/recalled.cpp
  src/ros/recorder_node.cpp
  src/ros/shared_scenario.cpp)
# The time-driven agent (doc/robots.md), selected by the agent's ~mode.
target_sources(variational_formation_ros PRIVATE src/ros/timed_agent_node.cpp src/ros/timed_agent_outputs.cpp
  src/ros/timed_agent_robot.cpp)
# The monitor's two modes over its shared wiring, and the bounded pool of service calls.
target_sources(variational_formation_ros PRIVATE src/ros/lockstep_monitor.cpp src/ros/monitor_commands.cpp
  src/ros/monitor_parameters.cpp src/ros/timed_monitor.cpp src/ros/monitor_outputs.cpp
  src/ros/monitor_shape.cpp src/ros/monitor_robots.cpp src/ros/monitor_goals.cpp src/ros/goal_server.cpp src/ros/monitor_safety.cpp
  src/ros/recorder_bag.cpp src/ros/recorder_commands.cpp
  src/ros/sensing_hub.cpp src/ros/foreign_formations.cpp src/ros/service_call.cpp src/ros/state_batch.cpp src/ros/periodic_call.cpp src/ros/pacer.cpp src/ros/trails.cpp)
add_dependencies(variational_formation_ros ${PROJECT_NAME}_gencfg)
# The bag writer's LZ4 frames (liblz4, Debian's liblz4-dev).
find_path(VF_LZ4_INCLUDE_DIR lz4frame.h)
find_library(VF_LZ4_LIBRARY lz4)
if(NOT VF_LZ4_INCLUDE_DIR OR NOT VF_LZ4_LIBRARY)
  message(FATAL_ERROR "liblz4 not found (lz4frame.h, liblz4): the recorder's bag writer needs it. Install "
    "Debian's liblz4-dev (scripts/test.sh installs it from package.xml's key liblz4-dev).")
endif()
target_include_directories(variational_formation_ros SYSTEM PRIVATE ${VF_LZ4_INCLUDE_DIR})
target_link_libraries(variational_formation_ros ${variational_formation_core_LIBRARIES} ${catkin_LIBRARIES}
  ${VF_LZ4_LIBRARY})
target_compile_options(variational_formation_ros PRIVATE ${VF_FLAGS})
add_dependencies(variational_formation_ros ${catkin_EXPORTED_TARGETS})

foreach(node agent monitor recorder agent_manager)
  add_executable(${node} src/ros/${node}_main.cpp)
  target_link_libraries(${node} variational_formation_ros)
  target_compile_options(${node} PRIVATE ${VF_FLAGS})
  install(TARGETS ${node} RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endforeach()
# The agent as a nodelet plugin (nodelet_plugins.xml), over the same AgentNode.
add_library(variational_formation_nodelets src/ros/agent_nodelet.cpp)
target_link_libraries(variational_formation_nodelets variational_formation_ros)
target_compile_options(variational_formation_nodelets PRIVATE ${VF_FLAGS})
install(TARGETS variational_formation_nodelets variational_formation_ros
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

if(CATKIN_ENABLE_TESTING)
  find_package(rostest REQUIRED)
  # One parametrised run test (test/ros/distributed_run.test), registered once per case.
  set(VF_RUN_CASES
    "scenario:=tetrahedron"
    "scenario:=tetrahedron_paper expect:=planar"
    "scenario:=hexagon"
    "scenario:=square"
    "scenario:=grid24"
    "scenario:=free_particle expect:=free_particle"
    # The scenario's own manoeuvre, with no command topic.
    "scenario:=hexagon_manoeuvre expect:=manoeuvre"
    "scenario:=hexagon order:=reverse stagger:=1"
    "scenario:=hexagon rate:=1 inject:=true"
    "scenario:=hexagon nodelet:=true inject:=true rate:=1"
    "scenario:=grid24 nodelet:=true"
    # Scale: a 3D lattice of 48 agents written by make_scenario, all in one manager.
    "scenario:=lattice48 nodelet:=true")
  vf_add_rostest_cases(test/ros/distributed_run.test ${VF_RUN_CASES})
  # Real faults (signals to the real processes) during recorded runs: test/ros/fault.test.
  vf_add_rostest_cases(test/ros/fault.test
    "fault:=kill_agent seed:=3" "fault:=kill_agent_twice seed:=5" "fault:=kill_two seed:=2"
    "fault:=stop_agent seed:=4" "fault:=kill_monitor seed:=6" "fault:=kill_recorder seed:=7"
    # 20 kills of one agent, unpaced: a state of a dead incarnation may be held only by its
    # neighbours (doc/distributed.md, recovery).
    "fault:=kill_agent kills:=20 seed:=17 rate:=0 test_scenario:=hexagon3000"
    # An agent killed while its recall holders are stopped: it must ask them again (doc/distributed.md, recovery).
    "fault:=kill_holders_stopped seed:=8")
  # Time-driven agents (test/ros/timed_run.test), hexagon at rate 1.
  vf_add_rostest_cases(test/ros/timed_run.test
    "case:=no_faults" "case:=faults delay:=0.05 jitter:=0.02 loss:=0.2"
    "case:=within_margin scenario_name:=timed_hexagon_kappa4"
    "case:=beyond_margin scenario_name:=timed_hexagon_kappa4 expect:=not_converged delay:=0.07"
    "case:=kill kill:=2 respawn_delay:=1.5"
    "case:=reconfigure scenario_name:=timed_hexagon_kappa4 delay:=0.07 reconfigure_kappa:=13"
    "case:=command command:=0.3_-0.2")
  add_rostest(test/ros/timed_bad_input.test)
  # kappa during a run with the real dynparam: an agent's server and the formation's (the monitor's).
  add_rostest(test/ros/kappa_reconfigure.test ARGS mode:=timed)
  add_rostest(test/ros/kappa_reconfigure.test ARGS mode:=lockstep)
  # Live commands in a recorded lockstep run (test/ros/manoeuvre_run.test): with bad ones; with
  # an agent and the monitor killed during the manoeuvre.
  add_rostest(test/ros/manoeuvre_run.test ARGS case:=live seed:=3)
  add_rostest(test/ros/manoeuvre_run.test ARGS case:=faults seed:=5 faults:=true)
  # Goals (move_to, /move_base_simple/goal) in a recorded lockstep run (test/ros/goal.test).
  add_rostest(test/ros/goal.test)
  # A goal at h = 0.02 with the default window, and one the run cannot reach (goal_window.test).
  add_rostest(test/ros/goal_window.test)
  # The monitor's markers and trails (no master).
  catkin_add_gtest(test_markers test/ros/test_markers.cpp)
  target_link_libraries(test_markers variational_formation_ros gtest_main)
  target_compile_options(test_markers PRIVATE ${VF_FLAGS})
  # The recorder's bag writer, read back by rosbag (no master).
  catkin_add_gtest(test_bag_writer test/ros/test_bag_writer.cpp)
  target_link_libraries(test_bag_writer variational_formation_ros gtest_main)
  target_compile_options(test_bag_writer PRIVATE ${VF_FLAGS})
  # The bounded pool of service calls (no master).
  catkin_add_gtest(test_call_pool test/ros/test_call_pool.cpp)
  target_link_libraries(test_call_pool variational_formation_ros gtest_main)
  target_compile_options(test_call_pool PRIVATE ${VF_FLAGS})
  # Simulated robots (test/ros/robots_run.test): the hexagon with holonomic robots and with
  # unicycles from seeded headings; ring7 (delay margin 0.05 s) with lags 0.1 and 0.3 s; the hexagon
  # in the MuJoCo world (doc/robots.md), unicycles and holonomic bases.
  vf_add_rostest_cases(test/ros/robots_run.test
    "case:=hexagon"
    "case:=hexagon_unicycle kinematics:=unicycle heading_seed:=7 world_frame:=map"
    "case:=hexagon_unicycle_command kinematics:=unicycle heading_seed:=9 command:=0.3_-0.2"
    "case:=ring7_lag01 scenario:=ring7 lag:=0.1 time_limit:=90 expect_lag_warning:=true"
    "case:=ring7_lag03 scenario:=ring7 lag:=0.3 time_limit:=90 expect_lag_warning:=true"
    "case:=ring7_unicycle_lag01 scenario:=ring7 lag:=0.1 kinematics:=unicycle heading_seed:=3 time_limit:=90 expect_lag_warning:=true"
    "case:=ring7_unicycle_lag03 scenario:=ring7 lag:=0.3 kinematics:=unicycle heading_seed:=5 time_limit:=90 expect_lag_warning:=true"
    "case:=mujoco_unicycle world:=mujoco kinematics:=unicycle heading_seed:=7"
    "case:=mujoco_holonomic world:=mujoco"
    # Unicycles from scattered starts with the safety filter (doc/robots.md, "Safety"): no contact.
    "case:=scatter6_unicycle_safety scenario:=${PROJECT_SOURCE_DIR}/test/ros/scatter6_safety.yaml kinematics:=unicycle heading_seed:=3 time_limit:=90"
    # The same in the MuJoCo world, where bodies really touch: 0 contacts (issue 33).
    "case:=mujoco_safety_scattered world:=mujoco kinematics:=unicycle scenario_dir:=test/ros scenario:=scattered6_safety time_limit:=90")
  # The monitor's safety report on a formation the filter blocks (closest approach, blocked).
  add_rostest(test/ros/safety_monitor.test)
  # One verdict per run (desired, mirror image, folded, still settling, not converged) everywhere.
  add_rostest(test/ros/verdict.test)
  # render_bag.py on a recorded hexagon: video length, frames, processes left, bad inputs; and on
  # robots.launch's wall-time bag: the video is the run from its first step, one name per robot.
  add_rostest(test/ros/render.test ARGS kind:=formation)
  add_rostest(test/ros/render.test ARGS kind:=robots)
  # The same with world:=mujoco: the world's markers (bodies, headings, contacts) in the bag and video.
  add_rostest(test/ros/render.test ARGS kind:=mujoco)
  # Local delivery in two agent_managers: subscribers outside get every state, a late one the newest.
  add_rostest(test/ros/local_delivery.test)
  # SIGKILL to the nodelet manager of every agent during a recorded run: test/ros/nodelet_fault.test.
  add_rostest(test/ros/nodelet_fault.test ARGS seed:=3)
  # SIGKILLs to one of two unpaced agent_managers: steps lost everywhere are computed again.
  add_rostest(test/ros/shard_fault.test ARGS seed:=1)
  # Lockstep with the safety filter on (test/ros/safety_run.test, doc/distributed.md "Sensing"):
  # the bag equals simulate, unpaced, and with a SIGKILL while the victim's filter binds.
  add_rostest(test/ros/safety_run.test ARGS rate:=0)
  add_rostest(test/ros/safety_run.test ARGS fault:=kill)
  add_rostest(test/ros/safety_run.test ARGS fault:=kill nodelet:=true)
  # Two formations with safety sent across each other keep r apart (avoid, doc/maths.md §10),
  # lockstep (equal to simulate until the filter binds on the other team) and timed.
  add_rostest(test/ros/cross_teams.test)
  add_rostest(test/ros/cross_teams.test ARGS mode:=timed)
  # Issue 50: a diverging run with the filter on ends by itself, in simulate and formation.launch.
  add_rostest(test/ros/diverging_safety.test)
  # live_tf: tf lookups at now() during a default run (/clock, /use_sim_time).
  foreach(t two_formations two_teams launch live_tf)
    add_rostest(test/ros/${t}.test)
  endforeach()
  # Agents on three network-namespace hosts sharing one master (needs root, as in CI). Not a
  # rostest: it starts its own masters inside the namespaces. Its result file is not named
  # rosunit-*.xml, which scripts/test.sh pairs with the rostest-*.xml wrappers.
  catkin_run_tests_target("unittest" multihost "unittest-multihost.xml"
    COMMAND "/usr/bin/python3 ${PROJECT_SOURCE_DIR}/test/ros/multihost_test.py --gtest_output=xml:${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/unittest-multihost.xml")
  # A 60-agent formation in three nodelet managers, a third on each of three namespace hosts, the
  # monitor and recorder on a fourth; one manager SIGKILLed mid-run (as root, like multihost).
  catkin_run_tests_target("unittest" sharded "unittest-sharded.xml"
    COMMAND "/usr/bin/python3 ${PROJECT_SOURCE_DIR}/test/ros/sharded_test.py --gtest_output=xml:${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/unittest-sharded.xml")
endif()

# robot_sim: one simulated holonomic robot (core PointRobot) per agent, with the interfaces of a
# real one (cmd_vel in; nav_msgs/Odometry and tf out).
add_executable(robot_sim src/ros/robot_sim_contacts.cpp src/ros/robot_sim_main.cpp src/ros/robot_sim_node.cpp)
target_link_libraries(robot_sim variational_formation_ros variational_formation_contacts ${catkin_LIBRARIES})
target_compile_options(robot_sim PRIVATE ${VF_FLAGS})
add_dependencies(robot_sim ${catkin_EXPORTED_TARGETS})
install(TARGETS robot_sim RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# The transport's ceiling for a nodelet run (benchmark/transport_ceiling.sh; the package's own
# AgentThreads, StateBatch and batch reading from variational_formation_ros), built for the
# checkout only, like benchmark_roa.
add_executable(benchmark_protocol benchmark/benchmark_protocol.cpp)
add_dependencies(benchmark_protocol ${catkin_EXPORTED_TARGETS})
target_link_libraries(benchmark_protocol variational_formation_tools ${variational_formation_core_LIBRARIES} ${catkin_LIBRARIES})
target_compile_options(benchmark_protocol PRIVATE ${VF_FLAGS})
add_executable(benchmark_transport benchmark/benchmark_transport.cpp)
add_dependencies(benchmark_transport ${catkin_EXPORTED_TARGETS})
target_link_libraries(benchmark_transport variational_formation_ros ${variational_formation_core_LIBRARIES} ${catkin_LIBRARIES})
target_compile_options(benchmark_transport PRIVATE ${VF_FLAGS})
