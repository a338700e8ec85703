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
# public headers in NAME/include and private ones in NAME/src. Installed (cmake --install) with
# its headers and exported as llsf::NAME in the llsfsim package (cmake/install.cmake).
function(llsf_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES" ${ARGN})
  add_library(llsf_${name} STATIC ${ARG_SOURCES})
  add_library(llsf::${name} ALIAS llsf_${name})
  target_include_directories(llsf_${name}
    PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
           $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  llsf_target_options(llsf_${name})
  llsf_install_library(llsf_${name} ${name})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
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
  install(DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/gen/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          FILES_MATCHING PATTERN "*.pb.h")
  # The .proto files beside them (to import from other messages).
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          FILES_MATCHING PATTERN "*.proto")
endfunction()
