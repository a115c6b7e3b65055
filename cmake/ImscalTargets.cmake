# Shared build settings for every imscal target.

# Compile options every imscal target gets: warnings (as errors in CI) and sanitizers.
add_library(imscal_build_options INTERFACE)
target_compile_options(imscal_build_options INTERFACE -Wall -Wextra)
if(IMSCAL_WERROR)
  target_compile_options(imscal_build_options INTERFACE -Werror)
endif()
if(IMSCAL_SANITIZE)
  # The ignorelist by its path from the build folder (Ninja compiles there), so that the command
  # line is the same in every checkout and a compiler cache can reuse the objects.
  set(ubsan_ignorelist ${PROJECT_SOURCE_DIR}/cmake/ubsan-ignorelist.txt)
  if(CMAKE_GENERATOR MATCHES "Ninja")
    file(RELATIVE_PATH ubsan_ignorelist ${CMAKE_BINARY_DIR} ${ubsan_ignorelist})
  endif()
  target_compile_options(imscal_build_options INTERFACE
    -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
    $<BUILD_INTERFACE:-fsanitize-ignorelist=${ubsan_ignorelist}>)
  target_link_options(imscal_build_options INTERFACE -fsanitize=address,undefined)
endif()

# Precompiled headers: the standard, Eigen, fmt and JSON headers nearly every translation unit
# includes are parsed once per target instead of once per file (about a third of the build time
# of a file here). `imscal_precompile(target [extra headers...])`.
option(IMSCAL_PCH "Precompile the common headers" ON)
set(IMSCAL_COMMON_HEADERS <algorithm> <cmath> <filesystem> <map> <optional> <string> <vector>
    <Eigen/Core> <Eigen/Geometry> <fmt/format.h> <nlohmann/json.hpp>)
function(imscal_precompile target)
  if(IMSCAL_PCH)
    target_precompile_headers(${target} PRIVATE ${IMSCAL_COMMON_HEADERS} ${ARGN})
  endif()
endfunction()

# One library per folder: every .cpp directly in the folder (a folder of headers only makes an
# INTERFACE target). Headers are included from the repository root: #include "ims/strapdown.hpp".
# Usage: imscal_folder_library(imscal_ims DEPENDS imscal_core Eigen3::Eigen ...
#                              [PRECOMPILE <extra headers to precompile>...])
# Installed (cmake/ImscalInstall.cmake), the headers sit in include/imscal with the same layout.
function(imscal_folder_library name)
  cmake_parse_arguments(ARG "" "" "DEPENDS;PRECOMPILE" ${ARGN})
  set(imscal_include_dirs $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
      $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/generated> $<INSTALL_INTERFACE:include/imscal>)
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  if(sources)
    add_library(${name} STATIC ${sources})
    # Linked into the Python module (a shared object) as well as into the executables.
    set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ${IMSCAL_PYTHON})
    imscal_precompile(${name} ${ARG_PRECOMPILE})
    target_include_directories(${name} PUBLIC ${imscal_include_dirs})
    target_link_libraries(${name} PUBLIC ${ARG_DEPENDS} PRIVATE imscal_build_options)
    if(IMSCAL_SANITIZE)
      target_link_libraries(${name} PUBLIC imscal_build_options)
    endif()
  else()
    add_library(${name} INTERFACE)
    target_include_directories(${name} INTERFACE ${imscal_include_dirs})
    target_link_libraries(${name} INTERFACE ${ARG_DEPENDS})
  endif()
  # imscal_calib is exported as imscal::calib.
  string(REPLACE "imscal_" "" export_name ${name})
  set_target_properties(${name} PROPERTIES EXPORT_NAME ${export_name})
  set_property(GLOBAL APPEND PROPERTY IMSCAL_LIBRARIES ${name})
endfunction()
