# `cmake --install <build> --prefix P`: the headers (P/include/imscal, the repository's layout),
# the static libraries (P/lib), the command line (P/bin), the shipped robots (P/share/imscal) and
# the CMake package (P/lib/cmake/imscal) with the imported targets imscal::core, imscal::ims,
# imscal::robot, imscal::calib, imscal::ident, imscal::sim, imscal::eval and imscal::online. A
# project uses them with find_package(imscal) and target_link_libraries(app PRIVATE imscal::robot);
# see examples/find_package/.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

get_property(imscal_libraries GLOBAL PROPERTY IMSCAL_LIBRARIES)
set_target_properties(imscal_build_options PROPERTIES EXPORT_NAME build_options)
install(TARGETS ${imscal_libraries} imscal_build_options EXPORT imscalTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION include/imscal)
install(TARGETS imscal RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
foreach(folder core ims robot calib ident sim eval online)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${folder}/ DESTINATION include/imscal/${folder}
          FILES_MATCHING PATTERN "*.hpp")
endforeach()
install(FILES ${PROJECT_BINARY_DIR}/generated/core/version.hpp DESTINATION include/imscal/core)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/datasets/robots/ DESTINATION ${CMAKE_INSTALL_DATADIR}/imscal/robots)

set(imscal_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/imscal)
install(EXPORT imscalTargets NAMESPACE imscal:: DESTINATION ${imscal_cmake_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/imscalConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/imscalConfig.cmake
                              INSTALL_DESTINATION ${imscal_cmake_dir}
                              PATH_VARS CMAKE_INSTALL_DATADIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/imscalConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/imscalConfig.cmake ${PROJECT_BINARY_DIR}/imscalConfigVersion.cmake
        DESTINATION ${imscal_cmake_dir})
