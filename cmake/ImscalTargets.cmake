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

# Fails the configuration when `target` links a library whose target name or file matches the
# regular expression MATCHING, directly or through any library it links: the targets'
# INTERFACE_LINK_LIBRARIES followed transitively (a static library's private dependencies are there too, as
# $<LINK_ONLY:...>), imported targets included.
# Usage: imscal_assert_not_linked(imscal_sim MATCHING "^Ceres::|^ceres$|/libceres")
function(imscal_assert_not_linked target)
  cmake_parse_arguments(ARG "" "MATCHING" "" ${ARGN})
  set(queue ${target})
  set(seen "")
  while(queue)
    list(POP_FRONT queue current)
    if(current IN_LIST seen)
      continue()
    endif()
    list(APPEND seen ${current})
    string(MAKE_C_IDENTIFIER "${current}" key)
    if(current MATCHES "${ARG_MATCHING}")
      set(chain ${current})
      while(DEFINED via_${key})  # back to `target` along the links that reached it
        set(step ${via_${key}})
        list(PREPEND chain ${step})
        string(MAKE_C_IDENTIFIER "${step}" key)
      endwhile()
      list(JOIN chain " -> " chain)
      message(FATAL_ERROR "${target} must not link ${current}, and does: ${chain}")
    endif()
    if(NOT TARGET ${current})
      continue()
    endif()
    get_target_property(links ${current} INTERFACE_LINK_LIBRARIES)
    if(NOT links)
      continue()
    endif()
    foreach(link IN LISTS links)
      # $<LINK_ONLY:x> and $<BUILD_INTERFACE:x> name x; other generator expressions stay as they
      # are (they name no target, so the walk ends there).
      string(REGEX REPLACE "^\\$<(LINK_ONLY|BUILD_INTERFACE):(.*)>$" "\\2" link "${link}")
      string(MAKE_C_IDENTIFIER "${link}" link_key)
      if(NOT link IN_LIST seen AND NOT DEFINED via_${link_key})
        set(via_${link_key} ${current})
      endif()
      list(APPEND queue ${link})
    endforeach()
  endwhile()
endfunction()
