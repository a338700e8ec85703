// SPDX-License-Identifier: MIT
// Three whole games pinned by their result hash: the shipped default scenario, the thesis' two
// robots (first variant, P3-P3) and the hackathon, each seed 1. A refactoring must leave them
// byte-identical; a change that alters a game on purpose (the world, the refbox, an agent or a
// skill) updates the pinned hash in the same commit and says why in its message.
#include <doctest/doctest.h>

#include <cstdint>
#include <string>

#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"

namespace llsf {
namespace {

struct Pinned {
  const char* scenario;
  std::uint64_t hash;
  int points;
};

}  // namespace

TEST_CASE("pinned whole games: default, thesis-two-robots and hackathon, seed 1") {
  const Pinned pinned[] = {
      {"scenarios/default.yaml", 0xe4543add43a98a10ULL, 163},
      {"scenarios/thesis-two-robots.yaml", 0x2fdbac0c610161e9ULL, 166},
      {"scenarios/hackathon.yaml", 0x90e306e1b7f4c859ULL, 0},
  };
  for (const Pinned& p : pinned) {
    INFO(p.scenario);
    const study::ScenarioFile file =
        study::load_scenario(std::string(LLSF_SOURCE_DIR "/") + p.scenario);
    const study::RunResult r = study::run_game(file.variants.front(), 1);
    CHECK(r.result_hash == p.hash);
    CHECK(r.points == p.points);
  }
}

}  // namespace llsf
