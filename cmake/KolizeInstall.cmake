# Installs headers, libraries and the CMake package `kolize` (kolizeConfig.cmake) that
# exports kolize::broadphase, kolize::narrowphase and kolize::engine.
include(CMakePackageConfigHelpers)

set(KOLIZE_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/kolize")
get_property(kolize_install_targets GLOBAL PROPERTY KOLIZE_INSTALL_TARGETS)
install(TARGETS ${kolize_install_targets}
    EXPORT kolizeTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT kolizeTargets NAMESPACE kolize:: DESTINATION ${KOLIZE_INSTALL_CMAKEDIR})

configure_package_config_file(cmake/kolizeConfig.cmake.in
    "${CMAKE_CURRENT_BINARY_DIR}/kolizeConfig.cmake"
    INSTALL_DESTINATION ${KOLIZE_INSTALL_CMAKEDIR})
write_basic_package_version_file("${CMAKE_CURRENT_BINARY_DIR}/kolizeConfigVersion.cmake"
    COMPATIBILITY SameMinorVersion)
install(FILES
    "${CMAKE_CURRENT_BINARY_DIR}/kolizeConfig.cmake"
    "${CMAKE_CURRENT_BINARY_DIR}/kolizeConfigVersion.cmake"
    cmake/KolizeBullet.cmake
    cmake/KolizeGmp.cmake
    DESTINATION ${KOLIZE_INSTALL_CMAKEDIR})
