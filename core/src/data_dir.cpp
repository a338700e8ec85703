// SPDX-License-Identifier: MIT
#include "llsf/core/data_dir.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

#ifndef LLSF_SOURCE_DATA_DIR
#error "LLSF_SOURCE_DATA_DIR must be defined by the build (core/CMakeLists.txt)"
#endif

namespace llsf::core {

std::string source_data_dir() { return LLSF_SOURCE_DATA_DIR; }

std::string data_dir() {
  // 1. The user's override.
  const char* env = std::getenv("LLSF_DATA_DIR");
  if (env != nullptr && *env != '\0') return env;
  // 2. Installed: <prefix>/bin/llsfsim finds <prefix>/share/llsfsim (relocatable: no prefix is
  // compiled in). /proc/self/exe is Linux's path of the running executable.
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const std::filesystem::path installed =
        (exe.parent_path() / ".." / "share" / "llsfsim").lexically_normal();
    if (std::filesystem::is_directory(installed, ec)) return installed.string();
  }
  // 3. A build-tree run: the source tree.
  return source_data_dir();
}

}  // namespace llsf::core
