# Python tests (unittest, no nose or pytest here), one result file each in the test results
# folder: unittest-<group>.xml. Not rosunit-*.xml, which scripts/test.sh pairs with rostest's
# wrappers. test/python/vf_harness.py is their shared harness.
if(CATKIN_ENABLE_TESTING)
  set(VF_PYTHON_TEST_GROUPS
    "python_helpers:test/python/test_helpers.py"
    "python_scripts:test/python/test_scripts.py"
    "python_render_inputs:test/python/test_render_inputs.py"
    "python_render_cut:test/python/test_render_cut.py"
    "package_dependencies:test/package/test_dependencies.py"
    "package_message_classes:test/package/test_message_classes.py"
    "package_catkin_lint:test/package/test_catkin_lint.py"
    "package_launch_files:test/package/test_launch_files.py"
    "package_install:test/package/test_install.py")
  foreach(group ${VF_PYTHON_TEST_GROUPS})
    string(REPLACE ":" ";" parts "${group}")
    list(GET parts 0 name)
    list(GET parts 1 file)
    set(result "${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/unittest-${name}.xml")
    catkin_run_tests_target("unittest" ${name} "unittest-${name}.xml"
      COMMAND "/usr/bin/python3 ${PROJECT_SOURCE_DIR}/test/python/run_tests.py ${result} ${PROJECT_SOURCE_DIR}/${file}")
  endforeach()
endif()
