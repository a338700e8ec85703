// SPDX-License-Identifier: MIT
// The natives of the Fawkes compatibility layer (fawkes.lua): reading a Lua module of the skill
// and module directories for `require`, and reading a Fawkes navgraph file (YAML) of the cfg
// directories for `fawkes.load_yaml_navgraph`. Both read only regular files inside those
// directories (no "..", no absolute names, no symbolic link out of them) and write nothing.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "engine_impl.h"
#include "llsf/core/input_file.h"

namespace llsf::lua {

namespace {

namespace fs = std::filesystem;
using Impl = SkillEngine::Impl;

// A navgraph file can be no bigger than a source file.
constexpr std::uint64_t kMaxNavgraphBytes = core::kMaxSourceBytes;

// `file` inside `dir` if it is a regular file there whose real path stays inside the real
// `dir` (a symbolic link out of it does not count); empty otherwise.
std::string contained_file(const std::string& dir, const std::string& relative) {
  std::error_code ec;
  const fs::path root = fs::canonical(dir, ec);
  if (ec) return {};
  const fs::path candidate = fs::path(dir) / relative;
  if (!fs::is_regular_file(candidate, ec)) return {};
  const fs::path real = fs::canonical(candidate, ec);
  if (ec) return {};
  const fs::path rel = real.lexically_relative(root);
  if (rel.empty() || *rel.begin() == "..") return {};
  return candidate.lexically_normal().string();
}

// A module name as `require` takes it: identifiers joined by dots ("fawkes.modinit").
bool valid_module_name(const std::string& name) {
  if (name.empty() || name.size() > 200 || name.front() == '.' || name.back() == '.') {
    return false;
  }
  char prev = '.';
  for (const char c : name) {
    const bool ident = std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-';
    if (!ident && c != '.') return false;
    if (c == '.' && prev == '.') return false;
    prev = c;
  }
  return true;
}

// A navgraph file name: a relative path without "..".
bool valid_relative_file(const std::string& name) {
  if (name.empty() || name.size() > 1000) return false;
  const fs::path p(name);
  if (p.is_absolute()) return false;
  for (const fs::path& part : p) {
    if (part == "..") return false;
  }
  return true;
}

// ---- require --------------------------------------------------------------------------------

// Finds and reads module `name` into e.module_text / e.module_path; false with e.cpp_error set
// (what was searched) if there is none.
bool find_module(Impl& e, const std::string& name) {
  e.module_text.clear();
  e.module_path.clear();
  if (!valid_module_name(name)) {
    e.cpp_error = "'" + name + "' is no module name (names are identifiers joined by dots)";
    return false;
  }
  std::string stem = name;
  for (char& c : stem) {
    if (c == '.') c = '/';
  }
  // The module directories first (Fawkes' package.path, the team's src/lua/), then the skill
  // directories.
  std::vector<std::string> dirs = e.config.module_dirs;
  dirs.insert(dirs.end(), e.config.skill_dirs.begin(), e.config.skill_dirs.end());
  for (std::size_t d = 0; d < dirs.size(); ++d) {
    const std::string& dir = dirs[d];
    e.module_in_skill_dir = d >= e.config.module_dirs.size();
    for (const std::string& rel : {stem + ".lua", stem + "/init.lua"}) {
      const std::string path = contained_file(dir, rel);
      if (path.empty()) continue;
      std::string error;
      e.module_text =
          core::try_read_input_file(path, core::kMaxSourceBytes, "Lua module", error).value_or("");
      if (!error.empty()) {
        e.cpp_error = error;
        return false;
      }
      e.module_path = e.display_path(path);
      return true;
    }
  }
  // (the files, not the directories: those may be a temporary copy's, e.g. llsfsim exercise)
  e.cpp_error = "no " + stem + ".lua or " + stem + "/init.lua in them";
  return false;
}

// read_module(name) -> text, path, in a skill directory (not a module directory)  |  nil, why
int native_read_module(lua_State* L) {
  std::size_t n = 0;
  const char* name = luaL_checklstring(L, 1, &n);
  Impl& e = Impl::of(L);
  bool found = false;
  try {
    found = find_module(e, std::string(name, n));
  } catch (const std::exception& ex) {
    e.cpp_error = ex.what();
  }
  if (!found) {
    lua_pushnil(L);
    lua_pushstring(L, e.cpp_error.c_str());
    return 2;
  }
  charge(L, static_cast<std::int64_t>(e.module_text.size() / 8), 2, "reading a module");
  lua_pushlstring(L, e.module_text.data(), e.module_text.size());
  lua_pushstring(L, e.module_path.c_str());
  lua_pushboolean(L, e.module_in_skill_dir ? 1 : 0);
  return 3;
}

// ---- navgraph -------------------------------------------------------------------------------

std::string at(const std::string& path, const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  if (m.line < 0) return path;
  return path + ":" + std::to_string(m.line + 1);
}

// Parses the Fawkes navgraph `text` (of file `path`) into e.navgraph; throws with file:line.
void parse_navgraph(Impl& e, const std::string& path, const std::string& text) {
  NavgraphData g;
  YAML::Node doc;
  try {
    doc = YAML::Load(text);
  } catch (const YAML::Exception& ex) {
    throw std::runtime_error(path + ":" + std::to_string(ex.mark.line + 1) + ": " + ex.msg);
  }
  if (!doc.IsMap()) throw std::runtime_error(path + ":1: a navgraph file is a map");
  const auto fail = [&](const YAML::Node& n, const std::string& what) {
    throw std::runtime_error(at(path, n) + ": " + what);
  };
  const auto scalar = [&](const YAML::Node& n, const std::string& what) {
    if (!n.IsScalar()) fail(n, what + " must be a scalar");
    return n.Scalar();
  };
  const auto number = [&](const YAML::Node& n, const std::string& what) {
    const std::string s = scalar(n, what);
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end == nullptr || *end != '\0' || !std::isfinite(v)) {
      fail(n, what + " must be a number (got '" + s + "')");
    }
    return v;
  };
  if (doc["graph-name"]) g.name = scalar(doc["graph-name"], "graph-name");
  if (doc["root"]) g.root = scalar(doc["root"], "root");
  const YAML::Node nodes = doc["nodes"];
  if (!nodes || !nodes.IsSequence()) fail(nodes ? nodes : doc, "'nodes' must be a list");
  for (const YAML::Node& n : nodes) {
    if (!n.IsMap()) fail(n, "a node must be a map {name: ..., pos: [x, y]}");
    NavgraphNode node;
    if (!n["name"]) fail(n, "a node needs a name");
    node.name = scalar(n["name"], "name");
    const YAML::Node pos = n["pos"];
    if (!pos || !pos.IsSequence() || pos.size() != 2) {
      fail(pos ? pos : n, "node '" + node.name + "': pos must be a list [x, y]");
    }
    node.x = number(pos[0], "node '" + node.name + "': pos[0]");
    node.y = number(pos[1], "node '" + node.name + "': pos[1]");
    node.unconnected = n.Tag() == "tag:fawkesrobotics.org,navgraph/unconnected";
    if (const YAML::Node props = n["properties"]) {
      if (!props.IsSequence()) fail(props, "node '" + node.name + "': properties must be a list");
      for (const YAML::Node& p : props) {
        if (p.IsScalar()) {
          node.properties.emplace_back(p.Scalar(), "true");
        } else if (p.IsMap()) {
          for (const auto& kv : p) {
            node.properties.emplace_back(scalar(kv.first, "a property name"),
                                         scalar(kv.second, "property '" + kv.first.Scalar() + "'"));
          }
        } else {
          fail(p, "node '" + node.name + "': a property is a name or {name: value}");
        }
      }
    }
    for (const NavgraphNode& other : g.nodes) {
      if (other.name == node.name) fail(n, "node '" + node.name + "' is defined twice");
    }
    g.nodes.push_back(std::move(node));
  }
  const auto known = [&](const std::string& name) {
    for (const NavgraphNode& n : g.nodes) {
      if (n.name == name) return true;
    }
    return false;
  };
  if (const YAML::Node edges = doc["connections"]) {
    if (!edges.IsSequence()) fail(edges, "'connections' must be a list");
    for (const YAML::Node& c : edges) {
      if (!c.IsSequence() || c.size() != 2) fail(c, "a connection is a list [from, to]");
      NavgraphEdge edge;
      edge.from = scalar(c[0], "a connection's node");
      edge.to = scalar(c[1], "a connection's node");
      edge.directed = c.Tag() == "tag:fawkesrobotics.org,navgraph/dir";
      for (const std::string& end : {edge.from, edge.to}) {
        if (!known(end)) fail(c, "connection to unknown node '" + end + "'");
      }
      g.edges.push_back(std::move(edge));
    }
  }
  // (a root that is no node is no error: Fawkes' root_node() is then an invalid node)
  e.navgraph = std::move(g);
}

// Finds `file` in the cfg directories and parses it into e.navgraph; false with e.cpp_error.
bool load_navgraph(Impl& e, const std::string& file) {
  if (!valid_relative_file(file)) {
    e.cpp_error = "'" + file + "': a navgraph file is named relative to the cfg directories, " +
                  "without '..'";
    return false;
  }
  std::string searched;
  for (const std::string& dir : e.config.cfg_dirs) {
    const std::string path = contained_file(dir, file);
    if (path.empty()) {
      if (!searched.empty()) searched += ", ";
      searched += (fs::path(dir) / file).lexically_normal().string();
      continue;
    }
    std::string error;
    const std::string text =
        core::try_read_input_file(path, kMaxNavgraphBytes, "navgraph file", error).value_or("");
    if (!error.empty()) {
      e.cpp_error = error;
      return false;
    }
    parse_navgraph(e, path, text);
    return true;
  }
  e.cpp_error = "no navgraph file '" + file + "' in the cfg directories (" +
                (searched.empty() ? std::string("none is set: skills.cfg_dirs") : searched) + ")";
  return false;
}

// navgraph(file) -> {name=, root=, nodes={{name=, x=, y=, unconnected=, properties={k=v}}},
// edges={{from, to, directed}}}; raises an error naming the file:line of a bad file.
int native_navgraph(lua_State* L) {
  std::size_t n = 0;
  const char* file = luaL_checklstring(L, 1, &n);
  Impl& e = Impl::of(L);
  bool ok = false;
  try {
    ok = load_navgraph(e, std::string(file, n));
  } catch (const std::exception& ex) {
    e.cpp_error = ex.what();
  }
  if (!ok) {
    lua_pushnil(L);
    lua_pushstring(L, e.cpp_error.c_str());
    return 2;
  }
  const NavgraphData& g = e.navgraph;
  charge(L, static_cast<std::int64_t>(g.nodes.size() * 20 + g.edges.size() * 5), 2,
         "loading a navgraph");
  lua_createtable(L, 0, 4);
  lua_pushstring(L, g.name.c_str());
  lua_setfield(L, -2, "name");
  lua_pushstring(L, g.root.c_str());
  lua_setfield(L, -2, "root");
  lua_createtable(L, static_cast<int>(g.nodes.size()), 0);
  for (std::size_t i = 0; i < g.nodes.size(); ++i) {
    const NavgraphNode& node = g.nodes[i];
    lua_createtable(L, 0, 5);
    lua_pushstring(L, node.name.c_str());
    lua_setfield(L, -2, "name");
    lua_pushnumber(L, node.x);
    lua_setfield(L, -2, "x");
    lua_pushnumber(L, node.y);
    lua_setfield(L, -2, "y");
    lua_pushboolean(L, node.unconnected ? 1 : 0);
    lua_setfield(L, -2, "unconnected");
    lua_createtable(L, 0, static_cast<int>(node.properties.size()));
    for (const auto& kv : node.properties) {
      lua_pushstring(L, kv.second.c_str());
      lua_setfield(L, -2, kv.first.c_str());
    }
    lua_setfield(L, -2, "properties");
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  lua_setfield(L, -2, "nodes");
  lua_createtable(L, static_cast<int>(g.edges.size()), 0);
  for (std::size_t i = 0; i < g.edges.size(); ++i) {
    const NavgraphEdge& edge = g.edges[i];
    lua_createtable(L, 3, 0);
    lua_pushstring(L, edge.from.c_str());
    lua_rawseti(L, -2, 1);
    lua_pushstring(L, edge.to.c_str());
    lua_rawseti(L, -2, 2);
    lua_pushboolean(L, edge.directed ? 1 : 0);
    lua_rawseti(L, -2, 3);
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  lua_setfield(L, -2, "edges");
  return 1;
}

// skiller() -> skill_string, status (0..3), error: the engine's own state, for the
// SkillerInterface "Skiller" (what the skill string the agent sent is doing).
int native_skiller(lua_State* L) {
  const Impl& e = Impl::of(L);
  lua_pushlstring(L, e.skill_string.data(), e.skill_string.size());
  lua_pushinteger(L, static_cast<lua_Integer>(e.status));
  lua_pushlstring(L, e.error.data(), e.error.size());
  return 3;
}

}  // namespace

void push_fawkes_natives(lua_State* L) {
  lua_pushcfunction(L, native_skiller);
  lua_setfield(L, -2, "skiller");
  lua_pushcfunction(L, native_read_module);
  lua_setfield(L, -2, "read_module");
  lua_pushcfunction(L, native_navgraph);
  lua_setfield(L, -2, "navgraph");
  // The Fawkes configuration values skills read with config:get_float(...) etc.
  const SkillEngineConfig& cfg = Impl::of(L).config;
  lua_createtable(L, 0, static_cast<int>(cfg.fawkes_config.size()));
  for (const auto& [path, value] : cfg.fawkes_config) {
    lua_pushlstring(L, value.data(), value.size());
    lua_setfield(L, -2, path.c_str());
  }
  lua_setfield(L, -2, "fawkes_config");
  lua_pushinteger(L, static_cast<lua_Integer>(1e9 / cfg.rate_hz));
  lua_setfield(L, -2, "cycle_ns");
}

}  // namespace llsf::lua
