// SPDX-License-Identifier: MIT
// A program on the installed llsfsim package: loads a scenario and plays its first minute, with
// nothing but the installed interface, <llsfsim/llsfsim.h> (docs/install.md).
#include <llsfsim/llsfsim.h>

#include <cstdio>
#include <cstdlib>
#include <string>

int main(int argc, char** argv) {
  // The library looks for its data (the skill library) in $LLSF_DATA_DIR, else beside the running
  // executable: this program is not installed there, so it names the package's data directory.
  ::setenv("LLSF_DATA_DIR", LLSFSIM_DATA_DIR, /*overwrite=*/0);
  const std::string file =
      argc > 1 ? argv[1] : std::string(std::getenv("LLSF_DATA_DIR")) + "/scenarios/default.yaml";
  try {
    llsfsim::Scenario s = llsfsim::Scenario::load(file).front();
    s.set_duration_s(60);
    const std::uint64_t seed = s.seeds().front();
    const llsfsim::Result r = llsfsim::play(s, seed);
    std::printf("llsfsim   %s\n", llsfsim::version().c_str());
    std::printf("data      %s\n", std::getenv("LLSF_DATA_DIR"));
    std::printf("scenario  %s, seed %llu, %.0f s\n", s.name().c_str(),
                static_cast<unsigned long long>(seed), s.duration_s());
    std::printf("points    %d\n", r.points);
    std::printf("products  %.0f P3\n", r.statistics.at("products_p3"));
    std::printf("result    %016llx\n", static_cast<unsigned long long>(r.hash));
  } catch (const llsfsim::Error& e) {
    std::fprintf(stderr, "llsfsim-example: %s\n", e.what());
    return 2;
  }
  return 0;
}
