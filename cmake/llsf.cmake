# SPDX-License-Identifier: MIT
# Shared build helpers: warnings, reproducible floating point, module libraries.

# Compile options every llsfsim target gets.
function(llsf_target_options target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -ffp-contract=off)
  if(LLSF_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(LLSF_ENABLE_ASSERTS)
    target_compile_definitions(${target} PUBLIC LLSF_ENABLE_ASSERTS=1)
  endif()
endfunction()

# llsf_module(NAME SOURCES ...): one folder = one library `llsf_NAME` (alias `llsf::NAME`) with
# public headers in NAME/include and private ones in NAME/src.
function(llsf_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES" ${ARGN})
  add_library(llsf_${name} STATIC ${ARG_SOURCES})
  add_library(llsf::${name} ALIAS llsf_${name})
  target_include_directories(llsf_${name}
    PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  llsf_target_options(llsf_${name})
endfunction()
