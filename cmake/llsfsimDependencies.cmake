# SPDX-License-Identifier: MIT
# The dependencies that bring no CMake target of their own (Lua, CLIPS, OMPL, libpqxx/libpq), as
# imported targets llsf_dep::*. The build links them by these names, and so the exported
# llsfsimTargets.cmake names only them, never a library path of the build machine; the installed
# package (llsfsimConfig.cmake) includes this same file, which finds them again where the package
# is used. Each is defined once (the file may be included twice).
include_guard(GLOBAL)

# Lua 5.4 (Debian liblua5.4-dev; CMake's FindLua).
if(NOT TARGET llsf_dep::lua)
  find_package(Lua 5.4 EXACT REQUIRED)
  add_library(llsf_dep::lua INTERFACE IMPORTED)
  target_link_libraries(llsf_dep::lua INTERFACE ${LUA_LIBRARIES})
  target_include_directories(llsf_dep::lua SYSTEM INTERFACE ${LUA_INCLUDE_DIR})
endif()

# CLIPS 6.30 (Debian libclips-dev: no pkg-config or CMake files and no libclips.so link, so the
# runtime libclips.so.6 is found before the static archive).
if(NOT TARGET llsf_dep::clips)
  find_path(LLSF_CLIPS_INCLUDE_DIR clips/clips.h REQUIRED)
  find_library(LLSF_CLIPS_LIBRARY NAMES libclips.so.6 clips REQUIRED)
  add_library(llsf_dep::clips INTERFACE IMPORTED)
  target_link_libraries(llsf_dep::clips INTERFACE ${LLSF_CLIPS_LIBRARY})
  # (/usr/include on Debian: adding it with -isystem would break the C++ library's
  # #include_next, so only a non-standard location is added.)
  if(NOT LLSF_CLIPS_INCLUDE_DIR IN_LIST CMAKE_CXX_IMPLICIT_INCLUDE_DIRECTORIES)
    target_include_directories(llsf_dep::clips SYSTEM INTERFACE ${LLSF_CLIPS_INCLUDE_DIR})
  endif()
endif()

# OMPL 1.5 (Debian libompl-dev: ompl-config.cmake gives paths, no imported target).
if(NOT TARGET llsf_dep::ompl)
  find_package(ompl REQUIRED)
  add_library(llsf_dep::ompl INTERFACE IMPORTED)
  target_link_libraries(llsf_dep::ompl INTERFACE ${OMPL_LIBRARIES})
  # SYSTEM: OMPL's headers must not trip our -Werror warnings.
  target_include_directories(llsf_dep::ompl SYSTEM INTERFACE ${OMPL_INCLUDE_DIRS})
endif()

# libpqxx 6.4 and libpq (Debian libpqxx-dev, libpq-dev; pkg-config).
if(NOT TARGET llsf_dep::pqxx)
  find_package(PkgConfig REQUIRED)
  pkg_check_modules(LLSF_PQXX REQUIRED libpqxx libpq)
  add_library(llsf_dep::pqxx INTERFACE IMPORTED)
  target_link_libraries(llsf_dep::pqxx INTERFACE ${LLSF_PQXX_LINK_LIBRARIES})
  target_include_directories(llsf_dep::pqxx SYSTEM INTERFACE ${LLSF_PQXX_INCLUDE_DIRS})
endif()
