# `cmake --install`: the library (bifilar::base, bifilar::pendulum, bifilar::fit and the umbrella
# bifilar::bifilar), its public headers under include/bifilar/, the CMake package
# (lib/cmake/bifilar: bifilarConfig.cmake, bifilarConfigVersion.cmake, bifilarTargets.cmake) and
# the `bifilar` program. A client writes
#   find_package(bifilar REQUIRED)
#   target_link_libraries(app PRIVATE bifilar::fit)
# and includes "bifilar/fit/trace_fit.h" (docs/developers.md, "The installed library").
#
# The source tree includes from its root ("fit/trace_fit.h"); installed, that root would collide
# with other projects' base/, fit/, so each public header is copied to include/bifilar/<path>
# with its own includes of bifilar's headers rewritten to "bifilar/<path>"
# (cmake/bifilar_install_headers.cmake, run by `cmake --install`). The sources stay as they are.
# The application layer (pipeline/) is not installed: it is the program's, not a library's API.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# The public headers, named one by one. Not installed: the private step headers of fit/
# (ellipse_steps.h, tensor_steps.h, trace_fit_steps.h), the solver-facing ones (trace_cost.h,
# solver_logging.h), pendulum/dop853.h, and base/ helpers that no public header uses. A public
# header that includes a header missing from this list fails `cmake --install` with its name
# (CTest install/consumer runs it).
set(BIFILAR_PUBLIC_HEADERS
  base/units.h
  base/user_error.h
  base/version.h
  pendulum/model.h
  pendulum/integrator.h
  pendulum/imu_data.h
  pendulum/simulate.h
  fit/trace_input.h
  fit/trace_fit.h
  fit/trace_guess.h
  fit/trace_synth.h
  fit/window.h
  fit/swing_axis.h
  fit/glitch.h
  fit/block_mean.h
  fit/residual_stats.h
  fit/amplitude_trend.h
  fit/ellipse.h
  fit/tensor.h
  fit/tensor_components.h
  fit/tensor_plan.h
  fit/physical.h
  fit/physical_check.h)

set(bifilar_installed_libraries bifilar_base bifilar_pendulum bifilar_fit)
foreach(target IN LISTS bifilar_installed_libraries)
  string(REPLACE "bifilar_" "" name ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  target_include_directories(${target} INTERFACE $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
endforeach()

# bifilar::bifilar: everything installed, for a client that does not want to choose.
add_library(bifilar_library INTERFACE)
set_target_properties(bifilar_library PROPERTIES EXPORT_NAME bifilar)
target_link_libraries(bifilar_library INTERFACE ${bifilar_installed_libraries})

install(TARGETS ${bifilar_installed_libraries} bifilar_library EXPORT bifilarTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS bifilar RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

install(CODE "set(BIFILAR_SOURCE_DIR \"${PROJECT_SOURCE_DIR}\")
set(BIFILAR_PUBLIC_HEADERS \"${BIFILAR_PUBLIC_HEADERS}\")
set(BIFILAR_INCLUDE_DESTINATION \"${CMAKE_INSTALL_INCLUDEDIR}\")")
install(SCRIPT ${PROJECT_SOURCE_DIR}/cmake/bifilar_install_headers.cmake)

set(bifilar_cmake_destination ${CMAKE_INSTALL_LIBDIR}/cmake/bifilar)
install(EXPORT bifilarTargets NAMESPACE bifilar:: DESTINATION ${bifilar_cmake_destination})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/bifilarConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/bifilarConfig.cmake
                              INSTALL_DESTINATION ${bifilar_cmake_destination})
# Before 1.0 a minor version may change the API (CHANGELOG.md), so 0.3.x satisfies 0.3 only.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/bifilarConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/bifilarConfig.cmake
              ${PROJECT_BINARY_DIR}/bifilarConfigVersion.cmake
        DESTINATION ${bifilar_cmake_destination})
