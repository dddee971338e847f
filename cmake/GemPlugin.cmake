# gem_add_plugin(NAME SOURCES a.cpp ... [CUDA_SOURCES b.cu ...])
# Builds a GEM plugin: a MODULE library libNAME.so that gem loads at run time (docs/plugins.md).
# It gets GEM's headers, its definitions (real type, version) and GEM_BUILDING_PLUGIN, which turns the
# GEM_REGISTER_* macros into entries of the plugin's own list (framework/plugin_api.hpp). Symbols
# are hidden but for the two entry points, so plugins never see each other's helpers.
# Used by find_package(gem) (installed) and by GEM's own tree (tests/plugins).
include_guard(GLOBAL)

function(gem_add_plugin name)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "" "SOURCES;CUDA_SOURCES")
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "gem_add_plugin(${name}): unexpected arguments ${ARG_UNPARSED_ARGUMENTS} (use SOURCES and CUDA_SOURCES)")
  endif()
  if(NOT ARG_SOURCES)
    message(FATAL_ERROR "gem_add_plugin(${name}): give SOURCES (at least the file with GEM_PLUGIN(\"name\", \"version\"))")
  endif()
  add_library(${name} MODULE ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE gem::gem_core)
  target_compile_definitions(${name} PRIVATE GEM_BUILDING_PLUGIN)
  target_compile_features(${name} PRIVATE cxx_std_20)
  set_target_properties(${name} PROPERTIES PREFIX "lib" CXX_VISIBILITY_PRESET hidden CUDA_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  if(ARG_CUDA_SOURCES)
    # The device half: built for GEM's own architectures, with the shared CUDA runtime (one runtime
    # in the process). The descriptor states the architectures; the loader checks them.
    if(NOT CMAKE_CUDA_COMPILER)
      message(FATAL_ERROR "gem_add_plugin(${name}): CUDA_SOURCES need CUDA enabled in the project (project(... LANGUAGES CXX CUDA))")
    endif()
    if(NOT GEM_BUILT_CUDA_ARCHITECTURES)
      message(FATAL_ERROR "gem_add_plugin(${name}): this GEM was built without its CUDA backend; CUDA_SOURCES cannot run")
    endif()
    find_package(CUDAToolkit REQUIRED)
    target_sources(${name} PRIVATE ${ARG_CUDA_SOURCES})
    target_link_libraries(${name} PRIVATE CUDA::cudart)
    set_target_properties(${name} PROPERTIES CUDA_ARCHITECTURES "${GEM_BUILT_CUDA_ARCHITECTURES}" CUDA_STANDARD 20
      CUDA_STANDARD_REQUIRED ON CUDA_RUNTIME_LIBRARY Shared POSITION_INDEPENDENT_CODE ON)
    target_compile_options(${name} PRIVATE $<$<COMPILE_LANGUAGE:CUDA>:--expt-relaxed-constexpr --fmad=false>)
    target_compile_definitions(${name} PRIVATE GEM_PLUGIN_CUDA_ARCHITECTURES="${GEM_BUILT_CUDA_ARCHITECTURES}")
  endif()
endfunction()
