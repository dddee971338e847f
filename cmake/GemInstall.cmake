# cmake --install BUILD --prefix P: the SDK a plugin is built against (docs/plugins.md).
#   P/bin/gem, P/lib/libgem_core.so (and libgem_cuda.so with the CUDA backend),
#   P/include/gem/{geometry,events,framework,broadphase}/**.hpp,
#   P/lib/cmake/gem/: gemConfig.cmake (find_package(gem)), gemTargets.cmake (gem::gem_core,
#   gem::gem, gem::gem_cuda), GemPlugin.cmake (gem_add_plugin).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(GEM_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/gem)
set(GEM_INSTALL_INCLUDEDIR include/gem)
if(GEM_HAVE_CUDA)
  set(GEM_BUILT_CUDA_ARCHITECTURES "${CMAKE_CUDA_ARCHITECTURES}")
else()
  set(GEM_BUILT_CUDA_ARCHITECTURES "")
endif()

# What an event or broadphase may include: the geometry, the event API and every event header (a
# plugin may build on a built-in evaluator), the framework's headers, and the broadphase interface.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/geometry ${PROJECT_SOURCE_DIR}/events ${PROJECT_SOURCE_DIR}/framework
  ${PROJECT_SOURCE_DIR}/broadphase DESTINATION ${GEM_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.hpp" PATTERN "*.cuh"
  PATTERN deprecated EXCLUDE)
# The forwarding headers of GEM 0.1's include paths ("framework/event_api.hpp"), for one release.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/framework/api/deprecated/ DESTINATION ${GEM_INSTALL_INCLUDEDIR})

# The scenarios (the thesis fields, studies, calibration): gem bench reads its scenes from here.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenarios DESTINATION ${CMAKE_INSTALL_DATADIR}/gem)

# gem finds libgem_core (and libgem_cuda) beside it, wherever the prefix is.
set_target_properties(gem PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
install(TARGETS gem_core gem EXPORT gemTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(TARGET gem_cuda)
  # Exported as gem::gem_cuda: a plugin's CUDA part links it (gem_add_plugin's CUDA_SOURCES).
  set_target_properties(gem_cuda PROPERTIES INSTALL_RPATH "$ORIGIN")
  install(TARGETS gem_cuda EXPORT gemTargets LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
endif()
install(EXPORT gemTargets NAMESPACE gem:: DESTINATION ${GEM_INSTALL_CMAKEDIR} FILE gemTargets.cmake)

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/gemConfig.cmake.in ${PROJECT_BINARY_DIR}/gemConfig.cmake
  INSTALL_DESTINATION ${GEM_INSTALL_CMAKEDIR} PATH_VARS GEM_INSTALL_INCLUDEDIR)
# The plugin ABI changes between minor versions; the loader checks it exactly at run time anyway.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/gemConfigVersion.cmake VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/gemConfig.cmake ${PROJECT_BINARY_DIR}/gemConfigVersion.cmake
  ${PROJECT_SOURCE_DIR}/cmake/GemPlugin.cmake DESTINATION ${GEM_INSTALL_CMAKEDIR})
