// SPDX-License-Identifier: MIT
// A program on the installed llsfsim package: loads a scenario and plays its first minute.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "llsf/core/data_dir.h"
#include "llsf/core/error.h"
#include "llsf/core/sim_time.h"
#include "llsf/core/version.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"

int main(int argc, char** argv) {
  // The library looks for its data (the skill library) in $LLSF_DATA_DIR, else beside the running
  // executable: this program is not installed there, so it names the package's data directory.
  ::setenv("LLSF_DATA_DIR", LLSFSIM_DATA_DIR, /*overwrite=*/0);
  const std::string file = argc > 1 ? argv[1] : llsf::core::data_dir() + "/scenarios/default.yaml";
  try {
    llsf::study::Scenario s = llsf::study::load_scenario(file).variants.front();
    s.duration = llsf::core::SimTime::from_sec(60);
    const llsf::study::RunResult r = llsf::study::run_game(s, s.seeds.front());
    std::printf("llsfsim   %s\n", std::string(llsf::core::kVersion).c_str());
    std::printf("data      %s\n", llsf::core::data_dir().c_str());
    std::printf("scenario  %s, seed %llu, %.0f s\n", s.name.c_str(),
                static_cast<unsigned long long>(s.seeds.front()), s.duration.seconds());
    std::printf("points    %d\n", r.points);
    std::printf("result    %016llx\n", static_cast<unsigned long long>(r.result_hash));
  } catch (const llsf::core::UserError& e) {
    std::fprintf(stderr, "llsfsim-example: %s\n", e.what());
    return 2;
  }
  return 0;
}
