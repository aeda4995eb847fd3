# Installation: `cmake --install build [--prefix DIR]` puts the programs in bin/, libfootfall.so
# (the C ABI) and the static C++ libraries in lib/, their headers in include/footfall/, a CMake
# package (find_package(footfall): footfall::client, footfall::steps, footfall::export,
# footfall::terrain, footfall::import, footfall::c) and a pkg-config file (footfall: the C ABI),
# and under share/footfall/ the sample data, the Python package with the Maya plugin, and the
# Blender add-on zip.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(FOOTFALL_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/footfall)
set(FOOTFALL_INSTALL_SHAREDIR ${CMAKE_INSTALL_DATADIR}/footfall)

# Installs the library `target` as footfall::<export_name> in the CMake package, with the
# headers under include_dir (a folder holding footfall/<part>/), when one is given.
function(footfall_install_library target export_name)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
  install(TARGETS ${target} EXPORT footfallTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  if(ARGC GREATER 2)
    install(DIRECTORY ${ARGV2}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
      FILES_MATCHING PATTERN "*.h")
  endif()
endfunction()

# The package files; called once every library is declared.
function(footfall_install_package)
  install(EXPORT footfallTargets NAMESPACE footfall:: DESTINATION ${FOOTFALL_INSTALL_CMAKEDIR})
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/footfallConfig.cmake.in
    ${PROJECT_BINARY_DIR}/footfallConfig.cmake INSTALL_DESTINATION ${FOOTFALL_INSTALL_CMAKEDIR})
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/footfallConfigVersion.cmake
    COMPATIBILITY SameMinorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/footfallConfig.cmake
    ${PROJECT_BINARY_DIR}/footfallConfigVersion.cmake DESTINATION ${FOOTFALL_INSTALL_CMAKEDIR})
  # The .pc file names its prefix relative to itself, so an installed tree can move.
  file(RELATIVE_PATH FOOTFALL_PC_TO_PREFIX /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
  configure_file(${PROJECT_SOURCE_DIR}/cmake/footfall.pc.in ${PROJECT_BINARY_DIR}/footfall.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/footfall.pc
    DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/data/ DESTINATION ${FOOTFALL_INSTALL_SHAREDIR}/data)
endfunction()
