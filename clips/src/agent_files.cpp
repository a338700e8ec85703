// SPDX-License-Identifier: MIT
// An agent's files (agent_files.h): directories expanded, texts in load order, path-loads
// followed.
#include "llsf/clips/agent_files.h"

#include <algorithm>
#include <filesystem>
#include <set>

#include "llsf/core/input_file.h"
#include "source_text.h"

namespace llsf::clips {

namespace fs = std::filesystem;

std::vector<std::string> expand_agent_files(const std::vector<std::string>& entries) {
  std::vector<std::string> out;
  for (const std::string& e : entries) {
    std::error_code ec;
    if (!fs::is_directory(e, ec)) {
      out.push_back(e);
      continue;
    }
    std::vector<std::string> dir;
    for (const auto& f : fs::directory_iterator(e, ec))
      if (f.is_regular_file() && f.path().extension() == ".clp") dir.push_back(f.path().string());
    std::sort(dir.begin(), dir.end());
    out.insert(out.end(), dir.begin(), dir.end());
  }
  return out;
}

namespace {

SourceFile read_source_file(const std::string& path) {
  std::string error;  // reported when the agent loads
  return {path,
          core::try_read_input_file(path, core::kMaxSourceBytes, "CLIPS file", error).value_or("")};
}

// The path-loads of `n` and the lists in it, in text order.
void collect_path_loads(const detail::SourceNode& n, std::vector<std::string>& out) {
  if (!n.is_list()) return;
  if (n.head() == "path-load" && n.items.size() >= 2 &&
      n.items[1].kind != detail::SourceNode::Kind::kList) {
    out.push_back(n.items[1].text);
  }
  for (const detail::SourceNode& c : n.items) collect_path_loads(c, out);
}

}  // namespace

std::vector<SourceFile> read_agent_sources(const std::vector<std::string>& entries) {
  std::vector<SourceFile> out;
  for (const std::string& f : expand_agent_files(entries)) out.push_back(read_source_file(f));
  return out;
}

std::vector<std::string> path_load_names(std::string_view code) {
  std::vector<std::string> out;
  for (const detail::SourceNode& form : detail::read_source(code)) collect_path_loads(form, out);
  return out;
}

std::vector<SourceFile> read_fawkes_sources(const std::string& agent_dir,
                                            const std::string& entry) {
  std::error_code ec;
  const fs::path dir = fs::weakly_canonical(agent_dir, ec);
  std::vector<SourceFile> out;
  std::set<std::string> seen;
  // Depth first, each file once: a file's own path-loads come right after it.
  auto visit = [&](auto&& self, const fs::path& file) -> void {
    std::error_code e;
    const fs::path p = fs::weakly_canonical(file, e);
    if (e || !fs::is_regular_file(p, e) || !seen.insert(p.string()).second) return;
    const auto [d_end, p_it] = std::mismatch(dir.begin(), dir.end(), p.begin(), p.end());
    if (d_end != dir.end()) return;  // outside the agent directory: the load refuses it
    out.push_back(read_source_file(file.string()));
    for (const std::string& name : path_load_names(out.back().text)) {
      const fs::path rel(name);
      self(self, rel.is_absolute() ? rel : fs::path(agent_dir) / rel);
    }
  };
  visit(visit, fs::path(entry));
  for (const std::string& f : expand_agent_files({fs::path(entry).parent_path().string()})) {
    std::error_code e;
    const fs::path p = fs::weakly_canonical(f, e);
    if (!e && !seen.contains(p.string())) out.push_back(read_source_file(f));
  }
  return out;
}

}  // namespace llsf::clips
