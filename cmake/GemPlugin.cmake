# gem_add_plugin(NAME SOURCES a.cpp ... [CUDA_SOURCES b.cu ...])
# Builds a GEM plugin: a MODULE library libNAME.so that gem loads at run time (docs/plugins.md).
# It gets GEM's headers, its definitions (real type, version) and GEM_BUILDING_PLUGIN, which turns the
# GEM_REGISTER_* macros (GEM_REGISTER_CUDA_* included) into entries of the plugin's own list
# (framework/api/plugin_api.hpp). Symbols are hidden but for the two entry points, so plugins never see
# each other's helpers.
#
# CUDA_SOURCES are built only where both GEM and this project have CUDA: GEM built with its CUDA
# backend (GEM_BUILT_CUDA_ARCHITECTURES) and the CUDA language enabled here (gem_enable_cuda()).
# Otherwise they are skipped with a message and the plugin is its CPU part alone: its events run on
# the CPU, and a cuda run that enables one is refused (auto falls back to the CPU).
# Used by find_package(gem) (installed) and by GEM's own tree (tests/).
include_guard(GLOBAL)

# gem_enable_cuda(): at the top level of a plugin's CMakeLists.txt, after find_package(gem). Enables
# CUDA for the plugin when this GEM has its CUDA backend and a CUDA compiler is found; sets
# GEM_PLUGIN_CUDA to ON then, else OFF. A macro: enable_language must run in the caller's scope.
macro(gem_enable_cuda)
  set(GEM_PLUGIN_CUDA OFF)
  if(GEM_BUILT_CUDA_ARCHITECTURES)
    include(CheckLanguage)
    check_language(CUDA)
    if(CMAKE_CUDA_COMPILER)
      if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
        set(CMAKE_CUDA_ARCHITECTURES "${GEM_BUILT_CUDA_ARCHITECTURES}")
      endif()
      enable_language(CUDA)
      # CMake 3.25 does not know nvcc's C++20 flag (nvcc 12+ has it), as in GEM's own build.
      if(NOT CMAKE_CUDA20_STANDARD_COMPILE_OPTION)
        set(CMAKE_CUDA20_STANDARD_COMPILE_OPTION "-std=c++20")
        set(CMAKE_CUDA20_EXTENSION_COMPILE_OPTION "-std=c++20")
      endif()
      set(GEM_PLUGIN_CUDA ON)
    else()
      message(STATUS "GEM plugin: no CUDA compiler found; plugins here build their CPU part only")
    endif()
  else()
    message(STATUS "GEM plugin: this GEM has no CUDA backend; plugins here build their CPU part only")
  endif()
endmacro()

function(gem_add_plugin name)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "" "SOURCES;CUDA_SOURCES")
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "gem_add_plugin(${name}): unexpected arguments ${ARG_UNPARSED_ARGUMENTS} (use SOURCES and CUDA_SOURCES)")
  endif()
  if(NOT ARG_SOURCES)
    message(FATAL_ERROR "gem_add_plugin(${name}): give SOURCES (at least the file with GEM_PLUGIN(\"name\", \"version\"))")
  endif()
  add_library(${name} MODULE ${ARG_SOURCES})
  # Configured without a build type, CMake adds no -O flag: such a plugin would run its events
  # unoptimised inside an optimised GEM. It gets Release's -O3 then; a build type given wins.
  if(NOT CMAKE_BUILD_TYPE AND NOT CMAKE_CONFIGURATION_TYPES)
    target_compile_options(${name} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:-O3>)
  endif()
  target_link_libraries(${name} PRIVATE gem::gem_core)
  target_compile_definitions(${name} PRIVATE GEM_BUILDING_PLUGIN)
  target_compile_features(${name} PRIVATE cxx_std_20)
  set_target_properties(${name} PROPERTIES PREFIX "lib" CXX_VISIBILITY_PRESET hidden CUDA_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  if(ARG_CUDA_SOURCES)
    get_property(languages GLOBAL PROPERTY ENABLED_LANGUAGES)
    if(NOT GEM_BUILT_CUDA_ARCHITECTURES OR NOT TARGET gem::gem_cuda)
      message(STATUS "gem_add_plugin(${name}): this GEM was built without its CUDA backend; CUDA_SOURCES skipped, CPU part only")
      return()
    endif()
    if(NOT "CUDA" IN_LIST languages)
      message(STATUS "gem_add_plugin(${name}): CUDA is not enabled in this project (call gem_enable_cuda()); CUDA_SOURCES skipped, CPU part only")
      return()
    endif()
    # The device half: built for GEM's own architectures, linked to GEM's CUDA library (the table
    # its drivers enter) and the shared CUDA runtime (one runtime in the process). The descriptor
    # states the architectures; the loader checks them.
    target_sources(${name} PRIVATE ${ARG_CUDA_SOURCES})
    target_link_libraries(${name} PRIVATE gem::gem_cuda CUDA::cudart)
    set_target_properties(${name} PROPERTIES CUDA_ARCHITECTURES "${GEM_BUILT_CUDA_ARCHITECTURES}" CUDA_STANDARD 20
      CUDA_STANDARD_REQUIRED ON CUDA_EXTENSIONS OFF CUDA_RUNTIME_LIBRARY Shared POSITION_INDEPENDENT_CODE ON)
    # As GEM's own device code: constexpr std:: helpers in device code, no FMA contraction.
    target_compile_options(${name} PRIVATE $<$<COMPILE_LANGUAGE:CUDA>:--expt-relaxed-constexpr --fmad=false>)
    target_compile_definitions(${name} PRIVATE GEM_PLUGIN_CUDA_ARCHITECTURES="${GEM_BUILT_CUDA_ARCHITECTURES}")
  endif()
endfunction()
