// SPDX-License-Identifier: MIT
// An agent's files: a scenario's `agent` list with its directories expanded, and the files'
// texts in the order the agent loads them (for the source checks, source_check.h).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace llsf::clips {

/// `entries` with every directory replaced by its *.clp files in name order (as a scenario's
/// `agent` list is read).
std::vector<std::string> expand_agent_files(const std::vector<std::string>& entries);

/// One agent source file: its name (as findings name it) and its text.
struct SourceFile {
  std::string name;
  std::string text;
};

/// The files of `entries` (expand_agent_files()) with their texts, in load order; a file that
/// cannot be read has the text "" (loading the agent reports why).
std::vector<SourceFile> read_agent_sources(const std::vector<std::string>& entries);

/// A Fawkes-style agent's files in the order it loads them (docs/fawkes.md): the entry file,
/// then each file a `(path-load FILE)` with a literal name loads (relative to `agent_dir`,
/// inside it), at the place of that call, the files it path-loads after it; then the other .clp
/// files of the entry file's directory in name order (a name computed at run time cannot be
/// followed). Texts as read_agent_sources().
std::vector<SourceFile> read_fawkes_sources(const std::string& agent_dir, const std::string& entry);

/// The literal file names of the `(path-load NAME)` calls in `code` (a symbol or a string), in
/// text order; calls in comments and strings do not count.
std::vector<std::string> path_load_names(std::string_view code);

}  // namespace llsf::clips
