# SPDX-License-Identifier: MIT
# `cmake --install`: the llsfsim command, the libraries (one header: include/llsfsim/llsfsim.h),
# the run-time data in share/llsfsim/ (where an installed llsfsim finds it: core/data_dir.h) and
# the CMake package `llsfsim` (find_package(llsfsim CONFIG), target llsf::llsfsim).
include(CMakePackageConfigHelpers)

# Run-time data, in the source tree's layout (scenario files name their agents relative to
# themselves, ../clips/agents/..., so the same relative paths work in both places).
set(LLSF_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/llsfsim)
install(DIRECTORY clips/agents DESTINATION ${LLSF_INSTALL_DATADIR}/clips)
install(DIRECTORY lua/skills DESTINATION ${LLSF_INSTALL_DATADIR}/lua)
install(DIRECTORY scenarios exercises experiments config DESTINATION ${LLSF_INSTALL_DATADIR})
# The viewer's bundle exists once `make viewer` ran (report --html and serve need it).
install(DIRECTORY viewer/dist DESTINATION ${LLSF_INSTALL_DATADIR}/viewer OPTIONAL)
install(FILES LICENSE README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})

# The package.
set(LLSF_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/llsfsim)
install(EXPORT llsfsimTargets NAMESPACE llsf:: DESTINATION ${LLSF_INSTALL_CMAKEDIR})
configure_package_config_file(cmake/llsfsimConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/llsfsimConfig.cmake
                              INSTALL_DESTINATION ${LLSF_INSTALL_CMAKEDIR}
                              PATH_VARS LLSF_INSTALL_DATADIR)
# The version policy (docs/install.md, "The version"): what the package promises is the one
# installed header, llsfsim/llsfsim.h, kept source- and link-compatible within a minor version
# (0.1.z); a program asking for 0.1 gets any 0.1.z, never 0.2.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/llsfsimConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/llsfsimConfig.cmake
              ${PROJECT_BINARY_DIR}/llsfsimConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/llsfsimDependencies.cmake
        DESTINATION ${LLSF_INSTALL_CMAKEDIR})
