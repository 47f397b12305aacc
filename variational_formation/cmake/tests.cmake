# gtest unit tests: one file per core concept, run by `catkin_make run_tests`.
if(CATKIN_ENABLE_TESTING)
  set(VF_CORE_TESTS formation force_model integrators metrics stability scenario free_particle lockstep simulation
    timed_agent link_faults point_robot unicycle_robot record_ledger layers manoeuvre lockstep_manoeuvre monitor
    rigidity slot_assignment shape_outcome safety_filter spatial_grid safety_scenario blocked_detector
    sparse_spectrum goal_steering timed_safety safety_watch sensing_board robot_shape_watch referee_ready
    local_exchange topic_audience yaml_text foreign_agents)
  foreach(name ${VF_CORE_TESTS} command_desk)
    vf_add_gtest(test_${name} test/core/test_${name}.cpp "${variational_formation_core_LIBRARIES}")
  endforeach()
  # The layer guard reads what the built core library links (test_layers.cpp).
  target_compile_definitions(test_layers PRIVATE VF_CORE_LIBRARY="$<TARGET_FILE:variational_formation_core>")
  # The protocol's event sequences and seeded interleavings, over shipped and generated formations
  # (test_command_desk above, and test_protocol, which generates formations with the tools).
  vf_add_gtest(test_protocol test/core/test_protocol.cpp variational_formation_tools)
  # robot_sim's body contacts, counted as the MuJoCo world counts them (no MuJoCo needed).
  vf_add_gtest(test_body_contacts test/world/test_body_contacts.cpp variational_formation_contacts)
  foreach(name simulate_cli simulate_safety simulate_manoeuvre)
    vf_add_gtest(test_${name} test/tools/test_${name}.cpp variational_formation_tools)
  endforeach()
endif()

# The documentation against the code (test/doc/test_docs.py): doc/ros_api.md lists exactly the
# parameters the nodes read, and README.md stays a front door. No ROS master; named like the
# multihost test (not rosunit-*.xml, which scripts/test.sh pairs with rostest wrappers).
if(CATKIN_ENABLE_TESTING)
  catkin_run_tests_target("unittest" docs "unittest-docs.xml"
    COMMAND "/usr/bin/python3 ${PROJECT_SOURCE_DIR}/test/doc/test_docs.py --gtest_output=xml:${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/unittest-docs.xml")
endif()

# Python tests of the plotting scripts and of scenario names (test/python), one JUnit file each
# (rosunit's --gtest_output, as the multihost test in cmake/ros.cmake).
if(CATKIN_ENABLE_TESTING)
  foreach(t plot_inputs scenario_names)
    catkin_run_tests_target("unittest" ${t} "unittest-${t}.xml"
      COMMAND "/usr/bin/python3 ${PROJECT_SOURCE_DIR}/test/python/test_${t}.py --gtest_output=xml:${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/unittest-${t}.xml")
  endforeach()
endif()
