// SPDX-License-Identifier: MIT
// `llsfsim exercise NN --skill FILE --submit URL --team NAME`: sends the skill file to a
// hackathon leaderboard (`llsfsim hackathon serve`, docs/hackathon-server.md) instead of playing.
#pragma once

#include <CLI/CLI.hpp>

#include <memory>
#include <ostream>
#include <string>

namespace llsf::app {

/// --submit and --team of `llsfsim exercise`.
struct SubmitOptions {
  std::string url;  ///< "" = play locally (no submission)
  std::string team;
};

/// Registers --submit URL and --team NAME on the exercise command.
std::shared_ptr<SubmitOptions> add_submit_options(CLI::App& app);

/// POSTs `skill_file` for `exercise` to the leaderboard at `o.url`; prints the submission's id
/// and the board's address. Returns 0 when queued, 2 when refused (the server's message), the
/// file cannot be read or the server cannot be reached.
int submit_skill(const SubmitOptions& o, const std::string& exercise, const std::string& skill_file,
                 std::ostream& out, std::ostream& err);

}  // namespace llsf::app
