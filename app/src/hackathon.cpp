// SPDX-License-Identifier: MIT
// The hackathon leaderboard: the HTTP routes (submit, boards, submissions), the queue of
// sandboxed workers and what their output means (hackathon.h, docs/hackathon-server.md).
#include "hackathon.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <utility>

#include "llsf/core/config.h"
#include "llsf/core/data_dir.h"
#include "llsf/core/error.h"
#include "llsf/study/batch.h"
#include "llsf/study/report.h"
#include "llsf/study/stats_store.h"

namespace llsf::app {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using study::Submission;
using study::SubmissionStatus;

std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

HttpAnswer json_answer(int status, const json& j) {
  return {status, "application/json", dump(j) + "\n"};
}

HttpAnswer error_answer(int status, const std::string& message) {
  return json_answer(status, json{{"error", message}});
}

std::int64_t now_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

/// The query's `key=value` pairs, percent- and '+'-decoded.
std::vector<std::pair<std::string, std::string>> parse_query(const std::string& q) {
  auto decode = [](std::string_view s) {
    std::string out;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s[i] == '+') {
        out += ' ';
      } else if (s[i] == '%' && i + 2 < s.size() &&
                 std::isxdigit(static_cast<unsigned char>(s[i + 1])) != 0 &&
                 std::isxdigit(static_cast<unsigned char>(s[i + 2])) != 0) {
        out += static_cast<char>(std::stoi(std::string(s.substr(i + 1, 2)), nullptr, 16));
        i += 2;
      } else {
        out += s[i];
      }
    }
    return out;
  };
  std::vector<std::pair<std::string, std::string>> out;
  std::size_t pos = 0;
  while (pos <= q.size() && !q.empty()) {
    const std::size_t amp = std::min(q.find('&', pos), q.size());
    const std::string_view part(q.data() + pos, amp - pos);
    const std::size_t eq = part.find('=');
    if (!part.empty()) {
      out.emplace_back(decode(part.substr(0, eq)),
                       eq == std::string_view::npos ? "" : decode(part.substr(eq + 1)));
    }
    pos = amp + 1;
  }
  return out;
}

std::string query_value(const std::string& q, const std::string& key) {
  for (const auto& [k, v] : parse_query(q)) {
    if (k == key) return v;
  }
  return "";
}

/// The team's file name reduced to a safe base name ("skill.lua" when nothing is left).
std::string safe_file_name(const std::string& name) {
  std::string base = fs::path(name).filename().string();
  std::string out;
  for (const char c : base) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isalnum(u) != 0 || c == '_' || c == '-' || c == '.') out += c;
  }
  while (!out.empty() && out.front() == '.') out.erase(out.begin());
  if (out.empty() || out.size() > 64) return "skill.lua";
  if (out.size() < 4 || out.substr(out.size() - 4) != ".lua") out += ".lua";
  return out;
}

/// The last `n` bytes of `text`, cut at a line start when possible.
std::string tail(const std::string& text, std::size_t n) {
  if (text.size() <= n) return text;
  std::string t = text.substr(text.size() - n);
  if (const std::size_t nl = t.find('\n'); nl != std::string::npos && nl + 1 < t.size()) {
    t = t.substr(nl + 1);
  }
  return "..." + t;
}

/// A submission as teams may see it: no content, no seeds; the result's runs numbered instead.
json public_json(const Submission& s, bool with_result) {
  json j{{"id", s.id},
         {"team", s.team},
         {"exercise", s.exercise},
         {"file_name", s.file_name},
         {"sha256", s.sha256},
         {"received", s.received},
         {"status", std::string(study::to_string(s.status))}};
  if (s.status == SubmissionStatus::kDone) {
    j["passed"] = s.passed;
    j["total"] = s.total;
    j["value"] = s.value ? json(*s.value) : json(nullptr);
    j["verdict"] = s.verdict;
    // Why a played submission did not pass, for the page: its first run not passed, by number
    // (never its seed): the error, else the verdict's `why`.
    if (s.verdict != "PASS") {
      const json r = json::parse(s.result, nullptr, false);
      if (r.is_object() && r.contains("runs") && r["runs"].is_array()) {
        int i = 0;
        for (const json& run : r["runs"]) {
          ++i;
          if (!run.is_object() || run.value("result", std::string()) == "PASS") continue;
          std::string why = run.value("error", std::string());
          if (why.empty()) why = run.value("why", std::string());
          if (why.empty()) why = run.value("score", std::string());
          j["reason"] = fmt::format("run {} of {}: {}", i, r["runs"].size(), tail(why, 400));
          break;
        }
      }
    }
  }
  if (!s.error.empty()) j["error"] = s.error;
  if (with_result && !s.result.empty()) {
    json r = json::parse(s.result, nullptr, false);
    if (r.is_object()) {
      r.erase("skill_file");
      if (r.contains("runs") && r["runs"].is_array()) {
        int i = 0;
        for (json& run : r["runs"]) {
          if (!run.is_object()) continue;
          run.erase("seed");
          run["run"] = ++i;
        }
      }
      j["result"] = r;
    }
  }
  return j;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Exercises and the workers' output

std::vector<BoardExercise> board_exercises(const std::string& root) {
  std::vector<BoardExercise> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(root, ec)) {
    const fs::path file = e.path() / "exercise.yaml";
    if (!e.is_directory() || !fs::is_regular_file(file)) continue;
    BoardExercise ex;
    ex.name = e.path().filename().string();
    try {
      const core::ConfigNode n = core::ConfigNode::load_file(file.string());
      ex.title = n.at("title").as_string();
      const core::ConfigNode goal = n.at("goal");
      if (goal["reach"].defined()) {
        ex.goal = "reach";
      } else if (goal["find"].defined()) {
        ex.goal = "find";
      } else {
        ex.goal = "points";
      }
    } catch (const core::ConfigError&) {
      continue;  // `llsfsim exercise --list` shows why; the board leaves it out
    }
    ex.better = ex.goal == "points" ? "higher" : "lower";
    out.push_back(std::move(ex));
  }
  std::sort(out.begin(), out.end(),
            [](const BoardExercise& a, const BoardExercise& b) { return a.name < b.name; });
  return out;
}

study::SubmissionOutcome outcome_of(const SandboxResult& r, const SandboxLimits& limits) {
  study::SubmissionOutcome o;
  const std::string err_tail = tail(r.err, 2000);
  if (!r.started) {
    o.status = SubmissionStatus::kFailed;
    o.error = "the worker did not start: " + r.error;
    return o;
  }
  if (r.timed_out) {
    o.status = SubmissionStatus::kTimeout;
    o.error = fmt::format(
        "killed after the wall-clock limit of {:g} s (a skill that never ends its game's "
        "seeds in time)",
        limits.wall_s);
    return o;
  }
  if (r.signal != 0) {
    o.status = SubmissionStatus::kFailed;
    if (r.signal == SIGXCPU || (r.signal == SIGKILL && r.wall_s >= limits.cpu_s)) {
      o.error = fmt::format("the worker used more than the CPU limit of {} s", limits.cpu_s);
    } else {
      o.error = fmt::format("the worker died of signal {} ({})", r.signal, strsignal(r.signal));
    }
    if (!err_tail.empty()) o.error += "\n" + err_tail;
    return o;
  }
  json j = json::parse(r.out, nullptr, false);
  if (!j.is_object() || !j.contains("runs") || !j["runs"].is_array()) {
    o.status = SubmissionStatus::kFailed;
    o.error = fmt::format("the worker exited with code {} without a result{}", r.exit_code,
                          r.out_truncated ? " (its output was cut at the cap)" : "");
    if (!err_tail.empty()) o.error += ":\n" + err_tail;
    return o;
  }
  o.status = SubmissionStatus::kDone;
  o.result = dump(j);
  o.better = j.value("better", std::string("lower"));
  o.verdict = j.value("verdict", std::string(""));
  o.total = static_cast<int>(j["runs"].size());
  int passed = 0;
  double sum = 0.0;
  int values = 0;
  for (const json& run : j["runs"]) {
    if (!run.is_object()) continue;
    if (run.value("result", std::string()) == "PASS") ++passed;
    if (run.contains("value") && run["value"].is_number()) {
      sum += run["value"].get<double>();
      ++values;
    }
  }
  o.passed = passed;
  if (values > 0) o.value = sum / values;
  if (!err_tail.empty() && o.verdict != "PASS") o.error = err_tail;
  return o;
}

// ---------------------------------------------------------------------------------------------
// The server

HackathonServer::HackathonServer(HackathonOptions options) : options_(std::move(options)) {
  HackathonOptions& o = options_;
  if (o.workers < 1 || o.workers > 256) throw core::UserError("--workers must be 1..256");
  if (o.limits.wall_s <= 0.0) throw core::UserError("--wall-limit must be > 0");
  if (o.limits.cpu_s < 1) throw core::UserError("--cpu-limit must be >= 1");
  if (o.max_skill_bytes < 1) throw core::UserError("--max-skill-bytes must be >= 1");
  if (o.max_per_minute < 1) throw core::UserError("--max-per-minute must be >= 1");
  try {
    seed_count_ = static_cast<int>(study::parse_seed_list(o.seeds).size());
  } catch (const core::UserError& e) {
    throw core::UserError(std::string("--seeds: ") + e.what());
  }
  if (seed_count_ < 1) throw core::UserError("--seeds: no seeds");
  root_ = o.exercises;
  if (root_.empty()) {
    const char* env = std::getenv("LLSF_EXERCISES_DIR");
    root_ = env != nullptr && *env != '\0' ? env : core::data_dir() + "/exercises";
  }
  std::error_code ec;
  root_ = fs::absolute(root_, ec).string();
  exercises_ = board_exercises(root_);
  if (exercises_.empty()) throw core::UserError("no exercises in " + root_ + " (--exercises)");
  program_ = o.worker_program;
  if (program_.empty()) {
    program_ = fs::read_symlink("/proc/self/exe", ec).string();
    if (ec) throw core::UserError("cannot find this program (/proc/self/exe): " + ec.message());
  }
  if (o.viewer.empty()) o.viewer = study::viewer_dir();
  store_ = std::make_unique<study::SubmissionStore>(o.db);

  ServerOptions so;
  so.bind = o.bind;
  so.port = o.port;
  so.db = o.db;
  so.viewer = o.viewer;
  // A JSON body holds the file escaped (up to 6 bytes per byte for control characters).
  so.max_body_bytes = o.max_skill_bytes * 6 + 4096;
  so.log = [this](const std::string& line) { log(line); };
  so.routes = [this](const HttpRequest& r) { return route(r); };
  server_ = std::make_unique<Server>(so);
}

HackathonServer::~HackathonServer() { stop(); }

void HackathonServer::log(const std::string& line) const {
  if (options_.log) {
    options_.log(line);
  } else {
    std::fprintf(stderr, "llsfsim hackathon: %s\n", line.c_str());
  }
}

std::string HackathonServer::url() const { return server_->url(); }
int HackathonServer::port() const { return server_->port(); }

void HackathonServer::start() {
  if (!workers_.empty()) return;
  if (const int n = store_->requeue_running(); n > 0) {
    log(fmt::format("{} submission(s) were running when the server stopped: queued again", n));
  }
  server_->start();
  stopping_ = false;
  for (int i = 0; i < options_.workers; ++i) workers_.emplace_back([this] { work(); });
}

void HackathonServer::stop() {
  if (server_) server_->stop();
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
  workers_.clear();
}

void HackathonServer::work() {
  while (!stopping_) {
    std::optional<Submission> s;
    try {
      s = store_->claim_next();
    } catch (const std::exception& e) {
      log(std::string("cannot read the queue: ") + e.what());
    }
    if (!s) {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, std::chrono::seconds(1), [this] { return stopping_.load(); });
      continue;
    }
    try {
      play(*s);
    } catch (const std::exception& e) {
      log(fmt::format("submission {}: {}", s->id, e.what()));
      study::SubmissionOutcome o;
      o.status = SubmissionStatus::kFailed;
      o.error = std::string("internal error: ") + e.what();
      store_->finish(s->id, o);
    }
  }
}

void HackathonServer::play(const Submission& s) {
  // The skill file in a fresh directory of its own, under the team's (safe) file name, so that
  // messages name the team's file.
  std::string templ = (fs::temp_directory_path() / "llsf-submission-XXXXXX").string();
  if (::mkdtemp(templ.data()) == nullptr) {
    throw std::runtime_error(std::string("cannot create a directory: ") + std::strerror(errno));
  }
  const std::string dir = templ;
  struct Cleanup {
    explicit Cleanup(std::string d) : dir(std::move(d)) {}
    std::string dir;
    Cleanup(const Cleanup&) = delete;
    Cleanup& operator=(const Cleanup&) = delete;
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cleanup{dir};
  const std::string file = safe_file_name(s.file_name);
  {
    std::ofstream f(fs::path(dir) / file, std::ios::binary);
    f << s.content;
    if (!f) throw std::runtime_error("cannot write " + dir + "/" + file);
  }
  const std::vector<std::string> argv = {program_, "exercise", s.exercise, "--exercises",
                                         root_,    "--skill",  file,       "--seeds",
                                         s.seeds,  "--jobs",   "1",        "--json"};
  const SandboxResult r =
      run_sandboxed(argv, dir, options_.limits, [this] { return stopping_.load(); });
  if (r.cancelled) return;  // the server stops: "running" stays, the next start re-queues it
  const study::SubmissionOutcome o = outcome_of(r, options_.limits);
  store_->finish(s.id, o);
  log(fmt::format("submission {} ({}, {}): {} {}/{} in {:.1f} s", s.id, s.team, s.exercise,
                  study::to_string(o.status), o.passed, o.total, r.wall_s));
}

const BoardExercise* HackathonServer::find_exercise(const std::string& name,
                                                    std::string& why) const {
  std::vector<const BoardExercise*> hits;
  for (const BoardExercise& e : exercises_) {
    if (e.name == name) return &e;
    if (!name.empty() && e.name.rfind(name, 0) == 0) hits.push_back(&e);
  }
  if (hits.size() == 1) return hits.front();
  std::string names;
  for (const BoardExercise& e : exercises_) names += (names.empty() ? "" : ", ") + e.name;
  why = (hits.empty() ? "unknown exercise '" + name + "'"
                      : "'" + name + "' names several exercises") +
        "; the exercises: " + names;
  return nullptr;
}

std::optional<HttpAnswer> HackathonServer::route(const HttpRequest& req) {
  const std::vector<std::string>& p = req.path;
  const bool get = req.method == "GET" || req.method == "HEAD";
  // The page: / and /leaderboard (the viewer's files stay below their own names).
  if (p.empty() || (p.size() == 1 && p[0] == "leaderboard")) {
    if (!get) return error_answer(405, "only GET is served here");
    std::ifstream f(fs::path(options_.viewer) / "leaderboard.html", std::ios::binary);
    if (!f) {
      return error_answer(404, "the leaderboard page is not built (run `make viewer`): " +
                                   (fs::path(options_.viewer) / "leaderboard.html").string() +
                                   " is missing");
    }
    return HttpAnswer{200, "text/html; charset=utf-8",
                      std::string(std::istreambuf_iterator<char>(f), {})};
  }
  if (p.size() < 2 || p[0] != "api" || p[1] != "hackathon") {
    if (!get) return error_answer(405, "only GET is served here");
    return std::nullopt;  // the viewer's routes and files
  }
  const std::size_t n = p.size();
  // POST /api/hackathon/submit
  if (n == 3 && p[2] == "submit") {
    if (req.method != "POST") return error_answer(405, "submit with POST (a JSON body)");
    return submit(req);
  }
  if (!get) return error_answer(405, "only GET is served here");
  // GET /api/hackathon/exercises
  if (n == 3 && p[2] == "exercises") {
    json a = json::array();
    for (const BoardExercise& e : exercises_) {
      a.push_back({{"name", e.name}, {"title", e.title}, {"goal", e.goal}, {"better", e.better}});
    }
    return json_answer(200, json{{"exercises", a},
                                 {"seeds", seed_count_},
                                 {"max_skill_bytes", options_.max_skill_bytes},
                                 {"max_per_minute", options_.max_per_minute}});
  }
  // GET /api/hackathon/board/{exercise}
  if (n == 4 && p[2] == "board") {
    std::string why;
    const BoardExercise* ex = find_exercise(p[3], why);
    if (ex == nullptr) return error_answer(404, why);
    return board(*ex);
  }
  // GET /api/hackathon/submissions[?exercise=NAME&limit=N]
  if (n == 3 && p[2] == "submissions") {
    std::string exercise = query_value(req.query, "exercise");
    if (!exercise.empty()) {
      std::string why;
      const BoardExercise* ex = find_exercise(exercise, why);
      if (ex == nullptr) return error_answer(404, why);
      exercise = ex->name;
    }
    int limit = 50;
    if (const std::string l = query_value(req.query, "limit"); !l.empty()) {
      try {
        limit = std::clamp(std::stoi(l), 1, 1000);
      } catch (const std::exception&) {
        return error_answer(400, "limit must be a number");
      }
    }
    json a = json::array();
    for (const Submission& s : store_->list(exercise, limit)) a.push_back(public_json(s, false));
    return json_answer(200, a);
  }
  // GET /api/hackathon/submissions/{id}
  if (n == 4 && p[2] == "submissions") {
    std::int64_t id = 0;
    try {
      std::size_t used = 0;
      id = std::stoll(p[3], &used);
      if (used != p[3].size()) throw std::invalid_argument(p[3]);
    } catch (const std::exception&) {
      return error_answer(400, "bad submission id '" + p[3] + "'");
    }
    const std::optional<Submission> s = store_->get(id);
    if (!s) return error_answer(404, fmt::format("no submission {}", id));
    return json_answer(200, public_json(*s, true));
  }
  return error_answer(404, "no such hackathon API route");
}

HttpAnswer HackathonServer::submit(const HttpRequest& req) {
  // The body: {"team": ..., "exercise": ..., "file_name": ..., "skill": "<the file>"}.
  if (!study::is_valid_utf8(req.body)) {
    return error_answer(400, "the request is not UTF-8 text: save the skill file as UTF-8");
  }
  const json body = json::parse(req.body, nullptr, false);
  if (!body.is_object()) {
    return error_answer(400,
                        "the body must be a JSON object {\"team\", \"exercise\", \"file_name\", "
                        "\"skill\"} (Content-Type: application/json)");
  }
  auto text = [&](const char* key) -> std::optional<std::string> {
    if (!body.contains(key)) return std::string();
    if (!body[key].is_string()) return std::nullopt;
    return body[key].get<std::string>();
  };
  const std::optional<std::string> team_in = text("team");
  const std::optional<std::string> exercise_in = text("exercise");
  const std::optional<std::string> file_in = text("file_name");
  const std::optional<std::string> skill = text("skill");
  if (!team_in || !exercise_in || !file_in || !skill) {
    return error_answer(400, "team, exercise, file_name and skill must be strings");
  }
  // The team: trimmed, 1..40 characters, no control characters.
  std::string team = *team_in;
  while (!team.empty() && std::isspace(static_cast<unsigned char>(team.back())) != 0) {
    team.pop_back();
  }
  while (!team.empty() && std::isspace(static_cast<unsigned char>(team.front())) != 0) {
    team.erase(team.begin());
  }
  if (team.empty()) return error_answer(400, "give a team name");
  if (team.size() > 40) return error_answer(400, "the team name is longer than 40 bytes");
  if (std::any_of(team.begin(), team.end(),
                  [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; })) {
    return error_answer(400, "the team name has control characters");
  }
  if (exercise_in->empty()) return error_answer(400, "name the exercise (e.g. 01)");
  std::string why;
  const BoardExercise* ex = find_exercise(*exercise_in, why);
  if (ex == nullptr) return error_answer(400, why);
  if (skill->empty()) return error_answer(400, "the skill file is empty");
  if (static_cast<std::int64_t>(skill->size()) > options_.max_skill_bytes) {
    return error_answer(413, fmt::format("the skill file is {} bytes; at most {} bytes",
                                         skill->size(), options_.max_skill_bytes));
  }
  if (skill->find('\0') != std::string::npos) {
    return error_answer(400, "the skill file has a NUL byte: it is not a text file");
  }
  const std::string file_name = file_in->empty() ? "skill.lua" : *file_in;
  if (file_name.size() > 200) return error_answer(400, "file_name is longer than 200 bytes");

  // Rate limit and insert as one step (two requests of a team cannot both slip through).
  const std::lock_guard lock(submit_mutex_);
  const std::int64_t now = now_ms();
  if (const int recent = store_->count_since(team, now - 60000);
      recent >= options_.max_per_minute) {
    return error_answer(429, fmt::format("team '{}' sent {} submissions in the last minute; at "
                                         "most {} a minute: try again in a minute",
                                         team, recent, options_.max_per_minute));
  }
  int queued = 0;
  for (const auto& [status, count] : store_->counts()) {
    if (status == "queued") queued = count;
  }
  if (queued >= options_.max_queued) {
    return error_answer(503, fmt::format("{} submissions are waiting; try again later", queued));
  }
  const std::int64_t id = store_->add(team, ex->name, file_name, *skill, options_.seeds, now);
  wake_.notify_one();
  return json_answer(202, json{{"id", id},
                               {"status", "queued"},
                               {"team", team},
                               {"exercise", ex->name},
                               {"sha256", study::sha256_hex(*skill)},
                               {"queued_before", queued},
                               {"url", fmt::format("/api/hackathon/submissions/{}", id)}});
}

HttpAnswer HackathonServer::board(const BoardExercise& ex) {
  json entries = json::array();
  for (const study::BoardEntry& e : study::rank_board(store_->done(ex.name))) {
    json j = public_json(e.best, false);
    j["rank"] = e.rank;
    j["submissions"] = e.submissions;
    entries.push_back(std::move(j));
  }
  json recent = json::array();
  for (const Submission& s : store_->list(ex.name, 30)) recent.push_back(public_json(s, false));
  json queue = json::object({{"queued", 0}, {"running", 0}});
  for (const auto& [status, count] : store_->counts()) {
    if (status == "queued" || status == "running") queue[status] = count;
  }
  return json_answer(200, json{{"exercise", ex.name},
                               {"title", ex.title},
                               {"goal", ex.goal},
                               {"better", ex.better},
                               {"seeds", seed_count_},
                               {"entries", entries},
                               {"recent", recent},
                               {"queue", queue}});
}

}  // namespace llsf::app
