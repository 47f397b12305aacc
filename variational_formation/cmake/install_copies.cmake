# Run at install time (install(SCRIPT), the last install rule of CMakeLists.txt). In the test
# workspace (scripts/common.sh) the package's entries are links to the repository's, and CMake
# installs a link as a link, even a folder named with a trailing slash: every link installed into
# the package's share folder (launch, config, package.xml, nodelet_plugins.xml) is replaced by a
# copy of what it points to, so that the install space works without the source tree.
set(vf_share "$ENV{DESTDIR}${CMAKE_INSTALL_PREFIX}/share/variational_formation")
file(GLOB vf_entries LIST_DIRECTORIES true "${vf_share}/*")
foreach(vf_entry ${vf_entries})
  if(IS_SYMLINK "${vf_entry}")
    get_filename_component(vf_target "${vf_entry}" REALPATH)
    get_filename_component(vf_name "${vf_entry}" NAME)
    get_filename_component(vf_target_name "${vf_target}" NAME)
    if(NOT vf_name STREQUAL vf_target_name)
      message(FATAL_ERROR "${vf_entry} links to ${vf_target}, whose name differs")
    endif()
    message(STATUS "Copying over the link: ${vf_entry}")
    file(REMOVE "${vf_entry}")
    file(COPY "${vf_target}" DESTINATION "${vf_share}")
  endif()
endforeach()
