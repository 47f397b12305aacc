# The two shapes every tool and gtest of the package takes, declared once.

# A command-line tool: a thin main over variational_formation_tools, installed beside the
# nodes so that `rosrun variational_formation <name>` finds it.
function(vf_add_tool name main)
  add_executable(${name} ${main})
  target_link_libraries(${name} variational_formation_tools)
  target_compile_options(${name} PRIVATE ${VF_FLAGS})
  install(TARGETS ${name} RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endfunction()

# A gtest of one source file over one of the package's libraries, run by `catkin_make
# run_tests`; VF_SOURCE_DIR points it at config/ and the test data. Nothing without testing.
function(vf_add_gtest name file library)
  if(NOT CATKIN_ENABLE_TESTING)
    return()
  endif()
  catkin_add_gtest(${name} ${file})
  target_link_libraries(${name} ${library} gtest_main)
  target_compile_options(${name} PRIVATE ${VF_FLAGS})
  target_compile_definitions(${name} PRIVATE VF_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endfunction()

# One rostest file run once per case, each case a string of launch arguments ("a:=1 b:=2").
function(vf_add_rostest_cases file)
  foreach(case ${ARGN})
    separate_arguments(args UNIX_COMMAND "${case}")
    add_rostest(${file} ARGS ${args})
  endforeach()
endfunction()
