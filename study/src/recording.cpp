// SPDX-License-Identifier: MIT
#include "llsf/study/recording.h"

#include "llsf/study/runner.h"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <unordered_map>

#include "llsf/core/error.h"
#include "llsf/planner/move_base.h"
#include "llsf/refbox/refbox.h"
#include "llsf/sim/hackathon_extension.h"

namespace llsf::study {

namespace {

using Json = nlohmann::ordered_json;  // keys in the order written (docs/recording.md)

/// `v` rounded to `decimals` places exactly as "%.*f" rounds it, -0 as 0: dump() then writes
/// the shortest text of that value ("1.5" for 1.500), the same number for every reader.
double fixed(double v, int decimals) {
  char buf[64];
  const auto [end, ec] =
      std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, decimals);
  if (ec != std::errc()) return v;  // too large for the buffer: far off the field anyway
  double out = v;
  std::from_chars(buf, end, out);
  return out == 0.0 ? 0.0 : out;
}

Json xy(core::Vec2 p) { return Json::array({fixed(p.x(), 3), fixed(p.y(), 3)}); }

int lamp(kinematic::LampState s) { return static_cast<int>(s); }  // 0 off, 1 on, 2 blink

const char* collision_kind(kinematic::CollisionKind k) {
  switch (k) {
    case kinematic::CollisionKind::kRobotRobot:
      return "robot-robot";
    case kinematic::CollisionKind::kRobotWall:
      return "robot-wall";
    case kinematic::CollisionKind::kRobotDevice:
      return "robot-device";
  }
  return "?";
}

/// A navigation outcome as skills see it (navigator():status()).
const char* nav_outcome(planner::NavOutcome o) {
  switch (o) {
    case planner::NavOutcome::kNoPath:
      return "NO_PATH";
    case planner::NavOutcome::kInvalidGoal:
      return "INVALID_GOAL";
    case planner::NavOutcome::kBlocked:
      return "BLOCKED";
    case planner::NavOutcome::kStuck:
      return "STUCK";
    default:
      return "?";  // not a failure: never recorded
  }
}

/// Appends `s` as a JSON string; text that is not plain ASCII goes through nlohmann (invalid
/// UTF-8 becomes U+FFFD, as in every other line).
void append_json_string(std::string& out, std::string_view s) {
  const bool ascii =
      std::all_of(s.begin(), s.end(), [](char c) { return static_cast<unsigned char>(c) < 0x80; });
  if (!ascii) {
    out += Json(std::string(s)).dump(-1, ' ', false, Json::error_handler_t::replace);
    return;
  }
  out += '"';
  for (const char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  out += '"';
}

/// Appends facts as a JSON list of [index,"text"] pairs.
void append_fact_list(std::string& out,
                      const std::vector<std::pair<std::int64_t, std::string>>& facts) {
  out += '[';
  for (std::size_t i = 0; i < facts.size(); ++i) {
    out += i > 0 ? ",[" : "[";
    out += std::to_string(facts[i].first);
    out += ',';
    append_json_string(out, facts[i].second);
    out += ']';
  }
  out += ']';
}

/// One robot's agent trace being collected for the current cycle (Recorder::agent_trace).
struct AgentFacts {
  const clips::AgentHost* host = nullptr;  // a new host (a reloaded agent): a snapshot is due
  bool snapshot_written = false;
  core::SimTime next_snapshot;
  std::int64_t first_added = -1;      // the cycle's first asserted index (-1: none yet)
  std::vector<std::int64_t> removed;  // retracted in the cycle, existed before it
  std::string fired;                  // the cycle's firings: ["rule",[i,j]],...
  std::vector<std::pair<std::int64_t, std::string>> added;  // buffer: the cycle's new facts
  std::vector<std::pair<std::int64_t, std::string>> all;    // buffer: a snapshot
};

}  // namespace

struct Recorder::Impl {
  gzFile file = nullptr;
  std::string path;
  std::int64_t lines = 0;
  core::SimTime period;
  core::SimTime next_frame;
  std::string line;  // reused
  // What the last frame / tick showed, to write only changes.
  std::unordered_map<std::uint32_t, std::pair<double, double>> puck_pos;
  std::array<kinematic::SignalLights, kinematic::kDeviceCount> lights{};
  bool lights_known = false;
  refbox::GamePhase phase = refbox::GamePhase::kPreGame;
  refbox::GameState state = refbox::GameState::kInit;
  bool state_known = false;
  bool plan_written = false;
  std::size_t awards = 0;
  std::map<std::uint32_t, refbox::PuckState> puck_states;
  std::map<std::uint32_t, int> delivered;
  std::int64_t dropped = 0;
  std::vector<std::string> robot_names;
  std::vector<std::vector<core::Vec2>> paths;  // per robot, as last written
  std::vector<int> nav_states;                 // per robot: move_base's state as last written
  std::vector<int> jam_device;                 // per robot, as last written (-1: not jammed)
  std::vector<std::int64_t> robot_dropped;     // per robot: its copies dropped so far
  sim::HackathonScore score;                   // hackathon: as last written
  bool score_known = false;
  LineSink sink;
  std::vector<AgentFacts> agent_facts;      // per robot index (agent_trace)
  std::vector<std::int64_t> camera_frames;  // per robot: the colour camera's frames seen
  std::vector<bool> sightings_shown;        // per robot: the last sightings line had pucks
  std::vector<std::int64_t> nav_failures;   // per robot: navigation failures written

  void write(const Json& j) {
    if (file == nullptr && !sink) return;
    // Invalid UTF-8 (a robot's or a skill's text) becomes U+FFFD instead of an exception.
    line = j.dump(-1, ' ', false, Json::error_handler_t::replace);
    write_line();
  }
  /// Writes `line` as it is (built by hand: the agent lines, many per game).
  void write_line() {
    if (file != nullptr && (gzwrite(file, line.data(), static_cast<unsigned>(line.size())) !=
                                static_cast<int>(line.size()) ||
                            gzputc(file, '\n') < 0)) {
      throw core::UserError(path + ": cannot write the recording");
    }
    if (sink) sink(line);
    ++lines;
  }
  /// An event line's start: {"t": .., "e": event}.
  static Json event(core::SimTime t, const char* name) {
    return Json{{"t", fixed(t.seconds(), 2)}, {"e", name}};
  }
};

Recorder::Recorder(const std::string& path, const sim::Game& game, const RecordingInfo& info,
                   double pose_rate_hz, LineSink sink)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  m.sink = std::move(sink);
  if (!path.empty()) {
    m.file = gzopen(path.c_str(), "wb6");
    if (m.file == nullptr) {
      throw core::UserError(path + ": cannot create the recording: " +
                            std::error_code(errno, std::generic_category()).message());
    }
  }
  m.paths.resize(static_cast<std::size_t>(game.robot_count()));
  m.nav_states.assign(static_cast<std::size_t>(game.robot_count()), -1);
  m.jam_device.assign(static_cast<std::size_t>(game.robot_count()), -1);
  m.robot_dropped.assign(static_cast<std::size_t>(game.robot_count()), 0);
  m.camera_frames.assign(static_cast<std::size_t>(game.robot_count()), 0);
  m.sightings_shown.assign(static_cast<std::size_t>(game.robot_count()), false);
  m.nav_failures.assign(static_cast<std::size_t>(game.robot_count()), 0);
  m.period = core::SimTime::period_of_hz(pose_rate_hz);
  m.next_frame = game.time();
  const kinematic::WorldConfig& w = game.config().world;
  Json h = {
      {"format", "llsfsim-recording"},
      {"version", kRecordingVersion},
      {"scenario", info.scenario},
      {"variant", info.variant},
      {"seed", info.seed},
      {"llsfsim", info.llsfsim_version},
      {"pose_hz", fixed(pose_rate_hz, 3)},
      {"field", {{"width", fixed(w.field.width_m, 3)}, {"height", fixed(w.field.height_m, 3)}}}};
  Json devices = Json::array();
  for (int i = 0; i < kinematic::kDeviceCount; ++i) {
    const kinematic::DeviceConfig& d = w.devices[static_cast<std::size_t>(i)];
    const core::OrientedBox box = d.footprint();
    devices.push_back(
        {{"name", kinematic::device_name(core::DeviceId(i))},
         {"x", fixed(d.pose.x, 3)},
         {"y", fixed(d.pose.y, 3)},
         {"ori", fixed(d.pose.theta, 3)},
         {"box", Json::array({fixed(box.pose.x, 3), fixed(box.pose.y, 3),
                              fixed(2.0 * box.half_extents.x(), 3),
                              fixed(2.0 * box.half_extents.y(), 3), fixed(box.pose.theta, 3)})}});
  }
  h["devices"] = std::move(devices);
  Json robots = Json::array();
  Json jerseys = Json::array();
  for (int i = 0; i < game.robot_count(); ++i) {
    m.robot_names.emplace_back(game.robot(i).name());
    robots.push_back(game.robot(i).name());
    jerseys.push_back(w.robots.at(static_cast<std::size_t>(i)).jersey_or(i));
  }
  h["robots"] = std::move(robots);
  h["jerseys"] = std::move(jerseys);
  h["robot_radius"] = fixed(w.robot.radius_m, 3);
  h["puck_radius"] = fixed(w.puck.radius_m, 4);
  // Extra obstacles and the hackathon's task (only when present; docs/recording.md).
  if (!w.obstacles.empty()) {
    Json obstacles = Json::array();
    for (const kinematic::ObstacleConfig& o : w.obstacles) {
      obstacles.push_back(
          {{"name", o.name},
           {"box", Json::array({fixed(o.pose.x, 3), fixed(o.pose.y, 3), fixed(o.size_x_m, 3),
                                fixed(o.size_y_m, 3), fixed(o.pose.theta, 3)})}});
    }
    h["obstacles"] = std::move(obstacles);
  }
  if (const sim::HackathonExtension* hackathon = sim::hackathon_of(game)) {
    const sim::HackathonLayout* layout = &hackathon->layout();
    const sim::HackathonConfig& hc = hackathon->config();
    const kinematic::Rect& a = hc.safe_area;
    Json colours = Json::array();
    for (const auto& c : hc.colours) colours.push_back({{"name", c.name}, {"decoy", c.decoy}});
    Json pucks = Json::object();
    for (const sim::HackathonPuck& p : layout->pucks) {
      pucks[std::to_string(p.id.value())] = hc.colours[static_cast<std::size_t>(p.colour)].name;
    }
    h["hackathon"] = {{"safe_area", Json::array({fixed(a.lo.x(), 3), fixed(a.lo.y(), 3),
                                                 fixed(a.hi.x(), 3), fixed(a.hi.y(), 3)})},
                      {"safe_place", hc.safe_place},
                      {"colours", std::move(colours)},
                      {"pucks", std::move(pucks)},
                      {"points_per_puck", hc.points_per_puck},
                      {"decoy_penalty", hc.decoy_penalty},
                      {"camera",
                       {{"range_m", fixed(hc.camera.range_m, 3)},
                        {"fov_deg", fixed(hc.camera.fov_rad * 180.0 / core::kPi, 3)}}}};
  }
  m.write(h);
}

Recorder::~Recorder() {
  try {
    close();
  } catch (...) {  // a destructor must not throw; close() explicitly to see write errors
  }
}

void Recorder::close() {
  if (impl_->file == nullptr) return;
  const int rc = gzclose(impl_->file);
  impl_->file = nullptr;
  if (rc != Z_OK) throw core::UserError(impl_->path + ": cannot finish the recording");
}

std::int64_t Recorder::lines() const { return impl_->lines; }

void Recorder::skill(const sim::SkillStatusChange& c) {
  Json j = Impl::event(c.time, "skill");
  j["robot"] = c.robot;
  j["status"] = lua::to_string(c.status);
  j["string"] = c.skill_string;
  if (!c.result.empty()) j["result"] = c.result;
  if (!c.error.empty()) j["error"] = c.error;
  impl_->write(j);
}

void Recorder::skill_state(const sim::SkillStateChange& c) {
  Json j = Impl::event(c.time, "skill_state");
  j["robot"] = c.robot;
  j["skill"] = c.skill;
  j["from"] = c.from;
  j["to"] = c.to;
  if (!c.via.empty()) j["via"] = c.via;
  impl_->write(j);
}

void Recorder::log(core::SimTime t, const std::string& robot, lua::LogLevel level,
                   std::string_view text) {
  static const char* const kLevels[] = {"debug", "info", "warn", "error"};
  Json j = Impl::event(t, "log");
  j["robot"] = robot;
  j["level"] = kLevels[std::min<std::size_t>(static_cast<std::size_t>(level), 3)];
  j["text"] = std::string(text);
  impl_->write(j);
}

void Recorder::verdict(core::SimTime t, const std::string& result, const std::string& score,
                       const std::string& why) {
  Json j = Impl::event(t, "verdict");
  j["result"] = result;
  j["score"] = score;
  if (!why.empty()) j["why"] = why;
  impl_->write(j);
}

void Recorder::agent_trace(int robot, const clips::TraceEvent& e) {
  using Kind = clips::TraceEvent::Kind;
  Impl& m = *impl_;
  if (m.file == nullptr && !m.sink) return;
  if (e.kind == Kind::kLog) {
    // Info and above come through the agent's log sink (agent()); CLIPS' watch output and
    // debug lines only through the trace.
    if (e.level == clips::LogLevel::kDebug)
      agent(clips::LogRecord{e.time, e.level, e.agent, e.text});
    return;
  }
  if (robot < 0) throw std::out_of_range("Recorder::agent_trace: robot index < 0");
  const auto r = static_cast<std::size_t>(robot);
  if (r >= m.agent_facts.size()) m.agent_facts.resize(r + 1);
  AgentFacts& a = m.agent_facts[r];
  switch (e.kind) {
    case Kind::kAssert:
      // Indices grow: the facts of the cycle still there at its end are those from the first.
      if (a.first_added < 0) a.first_added = e.fact;
      return;
    case Kind::kRetract:
      // Asserted and retracted in the same cycle: neither.
      if (a.first_added < 0 || e.fact < a.first_added) a.removed.push_back(e.fact);
      return;
    case Kind::kFire: {
      if (!a.fired.empty()) a.fired += ',';
      a.fired += '[';
      append_json_string(a.fired, e.name);
      a.fired += ",[";
      for (std::size_t i = 0; i < e.facts.size(); ++i) {
        if (i > 0) a.fired += ',';
        a.fired += std::to_string(e.facts[i]);
      }
      a.fired += "]]";
      return;
    }
    case Kind::kCycleEnd:
      break;
    default:
      return;
  }
  // The end of a cycle: its rules line, its fact delta, a snapshot when due.
  const bool new_host = e.host != a.host;
  a.host = e.host;
  const bool snapshot = !a.snapshot_written || new_host || e.time >= a.next_snapshot;
  if (a.fired.empty() && a.first_added < 0 && a.removed.empty() && !snapshot) return;
  a.added.clear();
  if (a.first_added >= 0 && e.host != nullptr) e.host->fact_texts(a.added, a.first_added);
  for (auto& f : a.added) clips::strip_addresses(f.second);
  a.first_added = -1;
  std::string head = "{\"t\":";
  head += Json(fixed(e.time.seconds(), 2)).dump();
  std::string robot_json;
  append_json_string(robot_json, e.agent);
  if (!a.fired.empty()) {
    m.line = head + ",\"e\":\"rules\",\"robot\":" + robot_json + ",\"fired\":[" + a.fired + "]}";
    m.write_line();
    a.fired.clear();
  }
  if (!a.added.empty() || !a.removed.empty()) {
    m.line = head + ",\"e\":\"fact\",\"robot\":" + robot_json;
    if (!a.added.empty()) {
      m.line += ",\"a\":";
      append_fact_list(m.line, a.added);
    }
    if (!a.removed.empty()) {
      m.line += ",\"r\":[";
      for (std::size_t i = 0; i < a.removed.size(); ++i) {
        if (i > 0) m.line += ',';
        m.line += std::to_string(a.removed[i]);
      }
      m.line += ']';
    }
    m.line += '}';
    m.write_line();
    a.added.clear();
    a.removed.clear();
  }
  if (snapshot && e.host != nullptr) {
    if (!a.snapshot_written || new_host) a.next_snapshot = e.time;
    a.snapshot_written = true;
    while (a.next_snapshot <= e.time) a.next_snapshot += kFactSnapshotPeriod;
    e.host->fact_texts(a.all);
    for (auto& f : a.all) clips::strip_addresses(f.second);
    m.line = head + ",\"e\":\"facts\",\"robot\":" + robot_json + ",\"facts\":";
    append_fact_list(m.line, a.all);
    m.line += '}';
    m.write_line();
  }
}

std::string recording_file_name(const std::string& scenario, const std::string& variant,
                                std::uint64_t seed) {
  std::string name = scenario.empty() ? "game" : scenario;
  if (!variant.empty()) name += "-" + variant;
  for (char& c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '.' || c == '_' || c == '-';
    if (!ok) c = '_';
  }
  return name + "-seed" + std::to_string(seed) + ".jsonl.gz";
}

void Recorder::agent(const clips::LogRecord& r) {
  Json j = Impl::event(r.time, "agent");
  j["robot"] = r.agent;
  j["level"] = clips::to_string(r.level);
  if (r.text.find("<Pointer-C-") == std::string_view::npos) {
    j["text"] = r.text;
  } else {  // e.g. (watch facts) output or a printout of a fact with a message in it
    std::string text(r.text);
    clips::strip_addresses(text);
    j["text"] = text;
  }
  impl_->write(j);
}

void Recorder::lock(const std::string& robot, const clips::LockEvent& e) {
  Json j = Impl::event(e.time, "lock");
  j["robot"] = robot;
  j["resource"] = e.resource;
  j["from"] = clips::to_string(e.from);
  j["to"] = clips::to_string(e.to);
  impl_->write(j);
}

void Recorder::issue(core::SimTime t, const RunIssue& i) {
  Json j = Impl::event(t, "issue");
  j["robot"] = i.robot;
  j["kind"] = to_string(i.kind);
  if (!i.rule.empty()) j["rule"] = i.rule;
  if (!i.file.empty()) j["place"] = i.place();
  if (!i.skill.empty()) j["skill"] = i.skill;
  if (i.reason != lua::FailReason::kNone) j["reason"] = lua::to_string(i.reason);
  j["text"] = i.text;
  // Noticed later than it happened (a lock held too long is found at the end).
  if (fixed(i.time_s, 2) < fixed(t.seconds(), 2)) j["time_s"] = fixed(i.time_s, 2);
  impl_->write(j);
}

void Recorder::note(core::SimTime t, const std::string& robot, const std::string& text) {
  Json j = Impl::event(t, "note");
  j["robot"] = robot;
  j["text"] = text;
  impl_->write(j);
}

void Recorder::frame(const sim::Game& game) {
  Impl& m = *impl_;
  const core::SimTime t = game.time();
  const refbox::Refbox& rb = game.refbox();
  const kinematic::World& world = game.world();

  // Events of this tick: game state, awards, lamps, RFID, collisions.
  if (!m.state_known || rb.phase() != m.phase || rb.state() != m.state) {
    m.state_known = true;
    m.phase = rb.phase();
    m.state = rb.state();
    Json j = Impl::event(t, "game");
    j["phase"] = refbox::to_string(m.phase);
    j["state"] = refbox::to_string(m.state);
    j["points"] = rb.points();
    m.write(j);
  }
  if (!m.plan_written && rb.params()) {
    m.plan_written = true;
    Json types = Json::object();
    for (int i = 0; i < refbox::kProductionMachineCount; ++i) {
      types[std::string(kinematic::device_name(core::DeviceId(i)))] =
          refbox::to_string(rb.params()->machine_types[static_cast<std::size_t>(i)]);
    }
    Json j = Impl::event(t, "plan");
    j["types"] = std::move(types);
    m.write(j);
  }
  const auto& awards = rb.awards();
  for (; m.awards < awards.size(); ++m.awards) {
    const refbox::PointsAward& a = awards[m.awards];
    Json j = Impl::event(t, "award");
    j["points"] = a.points;
    j["reason"] = refbox::to_string(a.reason);
    j["total"] = rb.points();
    if (a.device.valid()) j["device"] = kinematic::device_name(a.device);
    if (a.order.valid()) j["order"] = a.order.value();
    if (a.puck.valid()) j["puck"] = a.puck.value();
    m.write(j);
  }
  for (int i = 0; i < kinematic::kDeviceCount; ++i) {
    const kinematic::SignalLights l = world.lights(core::DeviceId(i));
    auto& last = m.lights[static_cast<std::size_t>(i)];
    if (m.lights_known && l == last) continue;
    last = l;
    Json j = Impl::event(t, "lights");
    j["d"] = kinematic::device_name(core::DeviceId(i));
    j["l"] = Json::array({lamp(l.red), lamp(l.yellow), lamp(l.green)});
    m.write(j);
  }
  m.lights_known = true;
  const kinematic::WorldEvents& ev = game.last_events();
  for (const kinematic::RfidEvent& e : ev.rfid) {
    Json j = Impl::event(t, "rfid");
    j["d"] = kinematic::device_name(e.device);
    j["puck"] = e.puck.value();
    j["in"] = e.kind == kinematic::RfidEventKind::kEntered;
    m.write(j);
  }
  for (const kinematic::CollisionEvent& c : ev.collisions) {
    Json j = Impl::event(t, "collision");
    j["kind"] = collision_kind(c.kind);
    j["robot"] = m.robot_names.at(c.robot.value());
    if (c.kind == kinematic::CollisionKind::kRobotRobot) {
      j["other"] = m.robot_names.at(c.other_robot.value());
    } else if (c.kind == kinematic::CollisionKind::kRobotDevice) {
      j["other"] = kinematic::device_name(c.device);
    }
    m.write(j);
  }

  // Jams of the robot profiles: when a robot jams at a device and when it gets free.
  for (int i = 0; i < game.robot_count(); ++i) {
    const int d = game.robot(i).jam_device();
    int& last = m.jam_device[static_cast<std::size_t>(i)];
    if (d == last) continue;
    const int device = d >= 0 ? d : last;
    last = d;
    Json j = Impl::event(t, "jam");
    j["robot"] = m.robot_names.at(static_cast<std::size_t>(i));
    j["d"] = kinematic::device_name(core::DeviceId(device));
    j["jammed"] = d >= 0;
    m.write(j);
  }

  // The colour camera's new frames (hackathon): its sightings in the field frame, written when a
  // frame saw pucks or the previous written one did. The navigators' refusals and failures.
  const sim::HackathonExtension* hackathon = sim::hackathon_of(game);
  for (int i = 0; i < game.robot_count(); ++i) {
    const auto r = static_cast<std::size_t>(i);
    const sim::RobotStack& stack = game.robot(i);
    if (const sim::ColourCamera* cam = hackathon != nullptr ? &hackathon->camera(i) : nullptr;
        cam != nullptr && cam->frames() != m.camera_frames[r]) {
      m.camera_frames[r] = cam->frames();
      const auto seen = cam->sightings();
      if (!seen.empty() || m.sightings_shown[r]) {
        m.sightings_shown[r] = !seen.empty();
        Json pucks = Json::array();
        for (const lua::ColourPuckSighting& p : seen) {
          const core::Vec2 at = cam->frame_pose().to_parent(p.position);
          pucks.push_back(Json::array({fixed(at.x(), 3), fixed(at.y(), 3), p.colour}));
        }
        Json j = Impl::event(cam->frame_time(), "sightings");
        j["robot"] = m.robot_names.at(r);
        j["pucks"] = std::move(pucks);
        m.write(j);
      }
    }
    for (; m.nav_failures[r] < stack.nav_failures(); ++m.nav_failures[r]) {
      const sim::NavFailure* f = stack.nav_failure(m.nav_failures[r]);
      if (f == nullptr) continue;  // more than kNavFailureMemory in one tick
      const bool refused = f->outcome == planner::NavOutcome::kInvalidGoal;
      Json j = Impl::event(f->time, "nav");
      j["robot"] = m.robot_names.at(r);
      j["kind"] = refused ? "refused" : "failed";
      j["outcome"] = nav_outcome(f->outcome);
      j["message"] = f->message;
      if (f->goal_known) {
        j["goal"] =
            Json::array({fixed(f->goal.x, 3), fixed(f->goal.y, 3), fixed(f->goal.theta, 3)});
      }
      if (!f->place.empty()) j["place"] = f->place;
      m.write(j);
    }
  }

  if (t < m.next_frame) return;
  while (m.next_frame <= t) m.next_frame += m.period;

  // Planned paths that changed since the last frame (empty while not navigating).
  for (int i = 0; i < game.robot_count(); ++i) {
    const sim::RobotStack& robot = game.robot(i);
    static const std::vector<core::Vec2> kNone;
    const std::vector<core::Vec2>& now = robot.nav_status().outcome == planner::NavOutcome::kRunning
                                             ? robot.nav_path().points
                                             : kNone;
    std::vector<core::Vec2>& last = m.paths[static_cast<std::size_t>(i)];
    if (now.size() == last.size() &&
        std::equal(now.begin(), now.end(), last.begin(),
                   [](const core::Vec2& a, const core::Vec2& b) { return (a - b).norm() < 1e-3; }))
      continue;
    last = now;
    Json points = Json::array();
    for (const core::Vec2& p : now) points.push_back(xy(p));
    Json j = Impl::event(t, "path");
    j["robot"] = m.robot_names.at(static_cast<std::size_t>(i));
    j["points"] = std::move(points);
    m.write(j);
  }

  // move_base-2013 level: its state when it changed (docs/recording.md), with the counters of
  // the current navigation.
  for (int i = 0; i < game.robot_count(); ++i) {
    const planner::MoveBaseNavigator* mb = game.robot(i).move_base();
    if (mb == nullptr) continue;
    const int state = static_cast<int>(mb->state());
    int& last = m.nav_states[static_cast<std::size_t>(i)];
    if (state == last) continue;
    last = state;
    const planner::MoveBaseStats& st = mb->stats();
    Json j = Impl::event(t, "move_base");
    j["robot"] = m.robot_names.at(static_cast<std::size_t>(i));
    j["state"] = planner::to_string(mb->state());
    j["recoveries"] = st.recoveries;
    j["rotations"] = st.rotate_recoveries;
    j["escapes"] = st.escapes;
    j["plans"] = st.plans;
    j["waypoints"] = st.waypoints;
    j["resends"] = st.resends;
    j["aborts"] = st.aborts;
    m.write(j);
  }

  // Pose frame: robots (true pose, believed pose, held puck), pucks that moved, removed pucks.
  Json robots = Json::array();
  for (int i = 0; i < game.robot_count(); ++i) {
    const core::Pose2D p = world.robot_pose(core::RobotId(i));
    const lua::PoseEstimate b = game.robot(i).pose();
    const auto held = game.puck_in_pocket(i);
    robots.push_back(
        Json::array({fixed(p.x, 3), fixed(p.y, 3), fixed(p.theta, 3), fixed(b.pose.x, 3),
                     fixed(b.pose.y, 3), fixed(b.pose.theta, 3), held ? held->value() : 0}));
  }
  Json f = {{"t", fixed(t.seconds(), 2)}, {"f", 1}, {"r", std::move(robots)}};
  Json moved = Json::array();
  Json removed = Json::array();
  std::unordered_map<std::uint32_t, bool> present;
  for (const core::PuckId id : world.pucks()) {
    const core::Vec2 p = world.puck_position(id);
    present[id.value()] = true;
    auto it = m.puck_pos.find(id.value());
    if (it != m.puck_pos.end() && std::abs(it->second.first - p.x()) < 0.001 &&
        std::abs(it->second.second - p.y()) < 0.001) {
      continue;
    }
    m.puck_pos[id.value()] = {p.x(), p.y()};
    moved.push_back(Json::array({id.value(), fixed(p.x(), 3), fixed(p.y(), 3)}));
  }
  for (auto it = m.puck_pos.begin(); it != m.puck_pos.end();) {
    if (present.count(it->first) == 0) {
      removed.push_back(it->first);
      it = m.puck_pos.erase(it);
    } else {
      ++it;
    }
  }
  if (!moved.empty()) f["p"] = std::move(moved);
  if (!removed.empty()) f["pr"] = std::move(removed);
  const std::int64_t dropped = game.hub().total_counters().dropped_total();
  if (dropped != m.dropped) {
    f["drops"] = dropped - m.dropped;
    m.dropped = dropped;
    // By sender robot: copies of its messages dropped on any link.
    const comm::Hub& hub = game.hub();
    Json by = Json::object();
    for (int i = 0; i < game.robot_count(); ++i) {
      const comm::PeerId from = game.robot_peer(i);
      std::int64_t n = 0;
      for (int to = 0; to < hub.peer_count(); ++to) {
        if (to != from.value()) n += hub.link_counters(from, comm::PeerId(to)).dropped_total();
      }
      std::int64_t& last = m.robot_dropped[static_cast<std::size_t>(i)];
      if (n != last) {
        by[m.robot_names.at(static_cast<std::size_t>(i))] = n - last;
        last = n;
      }
    }
    if (!by.empty()) f["drops_from"] = std::move(by);
  }
  m.write(f);

  // The hackathon score, at the frame rate, when it changed.
  if (const std::optional<sim::HackathonScore> score = sim::hackathon_score(game)) {
    if (!m.score_known || score->points != m.score.points || score->rescued != m.score.rescued ||
        score->decoys != m.score.decoys || score->in_safe_area != m.score.in_safe_area) {
      if (m.score_known || score->rescued != 0 || score->decoys != 0) {
        Json ids = Json::array();
        for (const core::PuckId id : score->in_safe_area) ids.push_back(id.value());
        Json j = Impl::event(t, "rescue");
        j["points"] = score->points;
        j["rescued"] = score->rescued;
        j["decoys"] = score->decoys;
        j["pucks"] = std::move(ids);
        m.write(j);
      }
      m.score = *score;
      m.score_known = true;
    }
  }

  // Puck states and orders, at the frame rate.
  for (const refbox::Puck& p : rb.pucks()) {
    auto it = m.puck_states.find(p.id.value());
    if (it != m.puck_states.end() && it->second == p.state) continue;
    m.puck_states[p.id.value()] = p.state;
    Json j = Impl::event(t, "puck");
    j["id"] = p.id.value();
    j["state"] = refbox::to_string(p.state);
    m.write(j);
  }
  for (const refbox::Order& o : rb.orders()) {
    if (!o.active) continue;
    auto it = m.delivered.find(o.id.value());
    if (it != m.delivered.end() && it->second == o.quantity_delivered) continue;
    m.delivered[o.id.value()] = o.quantity_delivered;
    Json j = Impl::event(t, "order");
    j["id"] = o.id.value();
    j["product"] = refbox::to_string(o.product);
    j["requested"] = o.quantity_requested;
    j["delivered"] = o.quantity_delivered;
    j["window"] = Json::array({o.window_begin_s, o.window_end_s});
    m.write(j);
  }
}

std::vector<RecordingLine> read_recording(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (f == nullptr) throw core::UserError(path + ": cannot open the recording");
  std::vector<RecordingLine> out;
  std::string line;
  char buf[65536];
  int number = 0;
  auto fail = [&](const std::string& what) {
    gzclose(f);
    throw core::UserError(path + ":" + std::to_string(number) + ": " + what);
  };
  while (true) {
    line.clear();
    bool got = false;
    while (gzgets(f, buf, sizeof buf) != nullptr) {
      got = true;
      line += buf;
      if (!line.empty() && line.back() == '\n') break;
    }
    int err = 0;
    gzerror(f, &err);
    if (err != Z_OK && err != Z_STREAM_END) fail("corrupt recording (compressed stream damaged)");
    if (!got) break;
    ++number;
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    if (line.empty()) continue;
    Json j;
    try {
      j = Json::parse(line);
    } catch (const Json::parse_error& e) {
      fail(std::string("not a JSON object (") + e.what() + ")");
    }
    if (!j.is_object()) fail("not a JSON object");
    RecordingLine r;
    if (number == 1) {
      const auto format = j.find("format");
      if (format == j.end() || *format != "llsfsim-recording") fail("not an llsfsim recording");
      const auto version = j.find("version");
      if (version == j.end() || *version != kRecordingVersion) {
        fail("recording version " + (version == j.end() ? "(none)" : version->dump()) +
             " (this llsfsim reads version " + std::to_string(kRecordingVersion) + ")");
      }
      r.kind = "header";
    } else {
      const auto t = j.find("t");
      if (t == j.end()) fail("a line without a time \"t\"");
      if (!t->is_number()) fail("bad time " + t->dump());
      r.t = t->get<double>();
      const auto e = j.find("e");
      if (j.contains("f")) {
        r.kind = "frame";
      } else if (e != j.end() && e->is_string() && !e->get_ref<const std::string&>().empty()) {
        r.kind = e->get<std::string>();
      } else {
        fail("a line that is neither a frame nor an event");
      }
    }
    r.json = std::move(line);
    out.push_back(std::move(r));
  }
  gzclose(f);
  if (out.empty()) throw core::UserError(path + ": empty recording");
  return out;
}

}  // namespace llsf::study
