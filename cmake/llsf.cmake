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
# public headers in NAME/include and private ones in NAME/src. Its archive is installed
# (cmake --install) and exported as llsf::NAME in the llsfsim package, as what llsf::llsfsim
# links; its headers are not installed (cmake/install.cmake).
function(llsf_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES" ${ARGN})
  add_library(llsf_${name} STATIC ${ARG_SOURCES})
  add_library(llsf::${name} ALIAS llsf_${name})
  target_include_directories(llsf_${name}
    PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
           $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  llsf_target_options(llsf_${name})
  # The archive is installed (the installed interface, llsf::llsfsim, links it); the module's
  # headers are not: only llsfsim/llsfsim.h is (docs/install.md).
  llsf_install_library(llsf_${name} ${name})
endfunction()

# llsf_install_library(TARGET EXPORT_NAME): TARGET installed and exported as llsf::EXPORT_NAME.
function(llsf_install_library target export_name)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
  install(TARGETS ${target} EXPORT llsfsimTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
endfunction()

# llsf_install_protos(TARGET EXPORT_NAME): a generated-messages library (proto/) installed with
# its generated headers; include path gen/ in the build tree, include/ when installed.
function(llsf_install_protos target export_name)
  target_include_directories(${target} SYSTEM PUBLIC
                             $<BUILD_INTERFACE:${CMAKE_CURRENT_BINARY_DIR}/gen>
                             $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  llsf_install_library(${target} ${export_name})
  # The .proto files (the messages' definitions, for tools of one's own that speak them), not the
  # generated headers: share/llsfsim/proto/<package>/.
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/ DESTINATION ${CMAKE_INSTALL_DATADIR}/llsfsim/proto
          FILES_MATCHING PATTERN "*.proto")
endfunction()
