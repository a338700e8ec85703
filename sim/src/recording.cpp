// SPDX-License-Identifier: MIT
#include "llsf/sim/recording.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <string_view>
#include <unordered_map>

#include "llsf/core/error.h"
#include "llsf/refbox/refbox.h"

namespace llsf::sim {

namespace {

std::string quote(std::string_view s) {
  std::string out = "\"";
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
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string num(double v, int decimals) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s(buf);
  if (s == "-0" || s == "-0.0" || s == "-0.00" || s == "-0.000") s.erase(0, 1);
  return s;
}

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

}  // namespace

struct Recorder::Impl {
  gzFile file = nullptr;
  std::string path;
  std::int64_t lines = 0;
  SimTime period;
  SimTime next_frame;
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
  std::vector<int> jam_device;                 // per robot, as last written (-1: not jammed)
  std::vector<std::int64_t> robot_dropped;     // per robot: its copies dropped so far
  HackathonScore score;                        // hackathon: as last written
  bool score_known = false;
  LineSink sink;

  void write(const std::string& s) {
    if (file == nullptr && !sink) return;
    if (file != nullptr &&
        (gzwrite(file, s.data(), static_cast<unsigned>(s.size())) != static_cast<int>(s.size()) ||
         gzputc(file, '\n') < 0)) {
      throw core::UserError(path + ": cannot write the recording");
    }
    if (sink) sink(s);
    ++lines;
  }
  std::string head(SimTime t, const char* event) {
    return "{\"t\": " + num(t.seconds(), 2) + ", \"e\": \"" + event + "\"";
  }
};

Recorder::Recorder(const std::string& path, const Game& game, const RecordingInfo& info,
                   double pose_rate_hz, LineSink sink)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  m.sink = std::move(sink);
  if (!path.empty()) {
    m.file = gzopen(path.c_str(), "wb6");
    if (m.file == nullptr) throw core::UserError(path + ": cannot create the recording");
  }
  m.paths.resize(static_cast<std::size_t>(game.robot_count()));
  m.jam_device.assign(static_cast<std::size_t>(game.robot_count()), -1);
  m.robot_dropped.assign(static_cast<std::size_t>(game.robot_count()), 0);
  m.period = SimTime::period_of_hz(pose_rate_hz);
  m.next_frame = game.time();
  const kinematic::WorldConfig& w = game.config().world;
  std::string h =
      "{\"format\": \"llsfsim-recording\", \"version\": " + std::to_string(kRecordingVersion) +
      ", \"scenario\": " + quote(info.scenario) + ", \"variant\": " + quote(info.variant) +
      ", \"seed\": " + std::to_string(info.seed) + ", \"llsfsim\": " + quote(info.llsfsim_version) +
      ", \"pose_hz\": " + num(pose_rate_hz, 3) +
      ", \"field\": {\"width\": " + num(w.field.width_m, 3) +
      ", \"height\": " + num(w.field.height_m, 3) + "}, \"devices\": [";
  for (int i = 0; i < kinematic::kDeviceCount; ++i) {
    const kinematic::DeviceConfig& d = w.devices[static_cast<std::size_t>(i)];
    const core::OrientedBox box = d.footprint();
    h += std::string(i ? ", " : "") +
         "{\"name\": " + quote(kinematic::device_name(core::DeviceId(i))) +
         ", \"x\": " + num(d.pose.x, 3) + ", \"y\": " + num(d.pose.y, 3) +
         ", \"ori\": " + num(d.pose.theta, 3) + ", \"box\": [" + num(box.pose.x, 3) + ", " +
         num(box.pose.y, 3) + ", " + num(2.0 * box.half_extents.x(), 3) + ", " +
         num(2.0 * box.half_extents.y(), 3) + ", " + num(box.pose.theta, 3) + "]}";
  }
  h += "], \"robots\": [";
  for (int i = 0; i < game.robot_count(); ++i) {
    m.robot_names.emplace_back(game.robot(i).name());
    h += std::string(i ? ", " : "") + quote(game.robot(i).name());
  }
  h += "], \"jerseys\": [";
  for (int i = 0; i < game.robot_count(); ++i) {
    h += std::string(i ? ", " : "") +
         std::to_string(w.robots.at(static_cast<std::size_t>(i)).jersey_or(i));
  }
  h += "], \"robot_radius\": " + num(w.robot.radius_m, 3) +
       ", \"puck_radius\": " + num(w.puck.radius_m, 4);
  // Extra obstacles and the hackathon's task (only when present; docs/recording.md).
  if (!w.obstacles.empty()) {
    h += ", \"obstacles\": [";
    for (std::size_t i = 0; i < w.obstacles.size(); ++i) {
      const kinematic::ObstacleConfig& o = w.obstacles[i];
      h += std::string(i ? ", " : "") + "{\"name\": " + quote(o.name) + ", \"box\": [" +
           num(o.pose.x, 3) + ", " + num(o.pose.y, 3) + ", " + num(o.size_x_m, 3) + ", " +
           num(o.size_y_m, 3) + ", " + num(o.pose.theta, 3) + "]}";
    }
    h += "]";
  }
  if (const HackathonLayout* layout = game.hackathon_layout()) {
    const HackathonConfig& hc = *game.config().hackathon;
    const kinematic::Rect& a = hc.safe_area;
    h += ", \"hackathon\": {\"safe_area\": [" + num(a.lo.x(), 3) + ", " + num(a.lo.y(), 3) + ", " +
         num(a.hi.x(), 3) + ", " + num(a.hi.y(), 3) + "], \"safe_place\": " + quote(hc.safe_place) +
         ", \"colours\": [";
    for (std::size_t i = 0; i < hc.colours.size(); ++i) {
      h += std::string(i ? ", " : "") + "{\"name\": " + quote(hc.colours[i].name) +
           ", \"decoy\": " + (hc.colours[i].decoy ? "true" : "false") + "}";
    }
    h += "], \"pucks\": {";
    for (std::size_t i = 0; i < layout->pucks.size(); ++i) {
      const HackathonPuck& p = layout->pucks[i];
      h += std::string(i ? ", " : "") + quote(std::to_string(p.id.value())) + ": " +
           quote(hc.colours[static_cast<std::size_t>(p.colour)].name);
    }
    h += "}, \"points_per_puck\": " + std::to_string(hc.points_per_puck) +
         ", \"decoy_penalty\": " + std::to_string(hc.decoy_penalty) + "}";
  }
  h += "}";
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

void Recorder::skill(const SkillStatusChange& c) {
  Impl& m = *impl_;
  std::string s = m.head(c.time, "skill") + ", \"robot\": " + quote(c.robot) + ", \"status\": \"" +
                  lua::to_string(c.status) + "\", \"string\": " + quote(c.skill_string);
  if (!c.result.empty()) s += ", \"result\": " + quote(c.result);
  if (!c.error.empty()) s += ", \"error\": " + quote(c.error);
  m.write(s + "}");
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
  impl_->write(impl_->head(r.time, "agent") + ", \"robot\": " + quote(r.agent) + ", \"level\": \"" +
               clips::to_string(r.level) + "\", \"text\": " + quote(r.text) + "}");
}

void Recorder::lock(const std::string& robot, const clips::LockEvent& e) {
  impl_->write(impl_->head(e.time, "lock") + ", \"robot\": " + quote(robot) +
               ", \"resource\": " + quote(e.resource) + ", \"from\": \"" +
               clips::to_string(e.from) + "\", \"to\": \"" + clips::to_string(e.to) + "\"}");
}

void Recorder::note(SimTime t, const std::string& robot, const std::string& text) {
  impl_->write(impl_->head(t, "note") + ", \"robot\": " + quote(robot) +
               ", \"text\": " + quote(text) + "}");
}

void Recorder::frame(const Game& game) {
  Impl& m = *impl_;
  const SimTime t = game.time();
  const refbox::Refbox& rb = game.refbox();
  const kinematic::World& world = game.world();

  // Events of this tick: game state, awards, lamps, RFID, collisions.
  if (!m.state_known || rb.phase() != m.phase || rb.state() != m.state) {
    m.state_known = true;
    m.phase = rb.phase();
    m.state = rb.state();
    m.write(m.head(t, "game") + ", \"phase\": " + quote(refbox::to_string(m.phase)) +
            ", \"state\": " + quote(refbox::to_string(m.state)) +
            ", \"points\": " + std::to_string(rb.points()) + "}");
  }
  if (!m.plan_written && rb.params()) {
    m.plan_written = true;
    std::string s = m.head(t, "plan") + ", \"types\": {";
    for (int i = 0; i < refbox::kProductionMachineCount; ++i) {
      s += std::string(i ? ", " : "") + quote(kinematic::device_name(core::DeviceId(i))) + ": " +
           quote(refbox::to_string(rb.params()->machine_types[static_cast<std::size_t>(i)]));
    }
    m.write(s + "}}");
  }
  const auto& awards = rb.awards();
  for (; m.awards < awards.size(); ++m.awards) {
    const refbox::PointsAward& a = awards[m.awards];
    std::string s = m.head(t, "award") + ", \"points\": " + std::to_string(a.points) +
                    ", \"reason\": " + quote(refbox::to_string(a.reason)) +
                    ", \"total\": " + std::to_string(rb.points());
    if (a.device.valid()) s += ", \"device\": " + quote(kinematic::device_name(a.device));
    if (a.order.valid()) s += ", \"order\": " + std::to_string(a.order.value());
    if (a.puck.valid()) s += ", \"puck\": " + std::to_string(a.puck.value());
    m.write(s + "}");
  }
  for (int i = 0; i < kinematic::kDeviceCount; ++i) {
    const kinematic::SignalLights l = world.lights(core::DeviceId(i));
    auto& last = m.lights[static_cast<std::size_t>(i)];
    if (m.lights_known && l == last) continue;
    last = l;
    m.write(m.head(t, "lights") + ", \"d\": " + quote(kinematic::device_name(core::DeviceId(i))) +
            ", \"l\": [" + std::to_string(lamp(l.red)) + ", " + std::to_string(lamp(l.yellow)) +
            ", " + std::to_string(lamp(l.green)) + "]}");
  }
  m.lights_known = true;
  const kinematic::WorldEvents& ev = game.last_events();
  for (const kinematic::RfidEvent& e : ev.rfid) {
    m.write(m.head(t, "rfid") + ", \"d\": " + quote(kinematic::device_name(e.device)) +
            ", \"puck\": " + std::to_string(e.puck.value()) +
            ", \"in\": " + (e.kind == kinematic::RfidEventKind::kEntered ? "true" : "false") + "}");
  }
  for (const kinematic::CollisionEvent& c : ev.collisions) {
    std::string s = m.head(t, "collision") + ", \"kind\": \"" + collision_kind(c.kind) +
                    "\", \"robot\": " + quote(m.robot_names.at(c.robot.value()));
    if (c.kind == kinematic::CollisionKind::kRobotRobot) {
      s += ", \"other\": " + quote(m.robot_names.at(c.other_robot.value()));
    } else if (c.kind == kinematic::CollisionKind::kRobotDevice) {
      s += ", \"other\": " + quote(kinematic::device_name(c.device));
    }
    m.write(s + "}");
  }

  // Jams of the robot profiles: when a robot jams at a device and when it gets free.
  for (int i = 0; i < game.robot_count(); ++i) {
    const int d = game.robot(i).jam_device();
    int& last = m.jam_device[static_cast<std::size_t>(i)];
    if (d == last) continue;
    const int device = d >= 0 ? d : last;
    last = d;
    m.write(m.head(t, "jam") +
            ", \"robot\": " + quote(m.robot_names.at(static_cast<std::size_t>(i))) +
            ", \"d\": " + quote(kinematic::device_name(core::DeviceId(device))) +
            ", \"jammed\": " + (d >= 0 ? "true" : "false") + "}");
  }

  if (t < m.next_frame) return;
  while (m.next_frame <= t) m.next_frame += m.period;

  // Planned paths that changed since the last frame (empty while not navigating).
  for (int i = 0; i < game.robot_count(); ++i) {
    const planner::Navigator& nav = game.robot(i).nav();
    static const std::vector<core::Vec2> kNone;
    const std::vector<core::Vec2>& now =
        nav.status().outcome == planner::NavOutcome::kRunning ? nav.path().points : kNone;
    std::vector<core::Vec2>& last = m.paths[static_cast<std::size_t>(i)];
    if (now.size() == last.size() &&
        std::equal(now.begin(), now.end(), last.begin(),
                   [](const core::Vec2& a, const core::Vec2& b) { return (a - b).norm() < 1e-3; }))
      continue;
    last = now;
    std::string e = m.head(t, "path") +
                    ", \"robot\": " + quote(m.robot_names.at(static_cast<std::size_t>(i))) +
                    ", \"points\": [";
    for (std::size_t k = 0; k < now.size(); ++k) {
      e += std::string(k ? ", " : "") + "[" + num(now[k].x(), 3) + ", " + num(now[k].y(), 3) + "]";
    }
    m.write(e + "]}");
  }

  // Pose frame: robots (true pose, believed pose, held puck), pucks that moved, removed pucks.
  std::string& s = m.line;
  s = "{\"t\": " + num(t.seconds(), 2) + ", \"f\": 1, \"r\": [";
  for (int i = 0; i < game.robot_count(); ++i) {
    const core::Pose2D p = world.robot_pose(core::RobotId(i));
    const lua::PoseEstimate b = game.robot(i).pose();
    const auto held = game.puck_in_pocket(i);
    s += std::string(i ? ", " : "") + "[" + num(p.x, 3) + ", " + num(p.y, 3) + ", " +
         num(p.theta, 3) + ", " + num(b.pose.x, 3) + ", " + num(b.pose.y, 3) + ", " +
         num(b.pose.theta, 3) + ", " + std::to_string(held ? held->value() : 0) + "]";
  }
  s += "]";
  std::string moved, removed;
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
    moved += std::string(moved.empty() ? "" : ", ") + "[" + std::to_string(id.value()) + ", " +
             num(p.x(), 3) + ", " + num(p.y(), 3) + "]";
  }
  for (auto it = m.puck_pos.begin(); it != m.puck_pos.end();) {
    if (present.count(it->first) == 0) {
      removed += std::string(removed.empty() ? "" : ", ") + std::to_string(it->first);
      it = m.puck_pos.erase(it);
    } else {
      ++it;
    }
  }
  if (!moved.empty()) s += ", \"p\": [" + moved + "]";
  if (!removed.empty()) s += ", \"pr\": [" + removed + "]";
  const std::int64_t dropped = game.hub().total_counters().dropped_total();
  if (dropped != m.dropped) {
    s += ", \"drops\": " + std::to_string(dropped - m.dropped);
    m.dropped = dropped;
    // By sender robot: copies of its messages dropped on any link.
    const comm::Hub& hub = game.hub();
    std::string by;
    for (int i = 0; i < game.robot_count(); ++i) {
      const comm::PeerId from = game.robot_peer(i);
      std::int64_t n = 0;
      for (int to = 0; to < hub.peer_count(); ++to) {
        if (to != from.value()) n += hub.link_counters(from, comm::PeerId(to)).dropped_total();
      }
      std::int64_t& last = m.robot_dropped[static_cast<std::size_t>(i)];
      if (n != last) {
        by += std::string(by.empty() ? "" : ", ") +
              quote(m.robot_names.at(static_cast<std::size_t>(i))) + ": " +
              std::to_string(n - last);
        last = n;
      }
    }
    if (!by.empty()) s += ", \"drops_from\": {" + by + "}";
  }
  m.write(s + "}");

  // The hackathon score, at the frame rate, when it changed.
  if (const std::optional<HackathonScore> score = game.hackathon_score()) {
    if (!m.score_known || score->points != m.score.points || score->rescued != m.score.rescued ||
        score->decoys != m.score.decoys || score->in_safe_area != m.score.in_safe_area) {
      if (m.score_known || score->rescued != 0 || score->decoys != 0) {
        std::string ids;
        for (const core::PuckId id : score->in_safe_area) {
          ids += (ids.empty() ? "" : ", ") + std::to_string(id.value());
        }
        m.write(m.head(t, "rescue") + ", \"points\": " + std::to_string(score->points) +
                ", \"rescued\": " + std::to_string(score->rescued) +
                ", \"decoys\": " + std::to_string(score->decoys) + ", \"pucks\": [" + ids + "]}");
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
    m.write(m.head(t, "puck") + ", \"id\": " + std::to_string(p.id.value()) +
            ", \"state\": " + quote(refbox::to_string(p.state)) + "}");
  }
  for (const refbox::Order& o : rb.orders()) {
    if (!o.active) continue;
    auto it = m.delivered.find(o.id.value());
    if (it != m.delivered.end() && it->second == o.quantity_delivered) continue;
    m.delivered[o.id.value()] = o.quantity_delivered;
    m.write(m.head(t, "order") + ", \"id\": " + std::to_string(o.id.value()) +
            ", \"product\": " + quote(refbox::to_string(o.product)) +
            ", \"requested\": " + std::to_string(o.quantity_requested) +
            ", \"delivered\": " + std::to_string(o.quantity_delivered) + ", \"window\": [" +
            std::to_string(o.window_begin_s) + ", " + std::to_string(o.window_end_s) + "]}");
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
    if (line.front() != '{' || line.back() != '}') fail("not a JSON object");
    RecordingLine r;
    r.json = line;
    auto field = [&](std::string_view key) -> std::string {
      const std::string k = "\"" + std::string(key) + "\": ";
      const auto p = line.find(k);
      if (p == std::string::npos) return {};
      std::size_t b = p + k.size();
      std::size_t e = b;
      if (line[b] == '"') {
        e = line.find('"', b + 1);
        return e == std::string::npos ? std::string() : line.substr(b + 1, e - b - 1);
      }
      while (e < line.size() && line[e] != ',' && line[e] != '}') ++e;
      return line.substr(b, e - b);
    };
    if (number == 1) {
      if (field("format") != "llsfsim-recording") fail("not an llsfsim recording");
      if (field("version") != std::to_string(kRecordingVersion)) {
        fail("recording version " + field("version") + " (this llsfsim reads version " +
             std::to_string(kRecordingVersion) + ")");
      }
      r.kind = "header";
    } else {
      const std::string t = field("t");
      if (t.empty()) fail("a line without a time \"t\"");
      try {
        r.t = std::stod(t);
      } catch (const std::exception&) {
        fail("bad time '" + t + "'");
      }
      r.kind = line.find("\"f\": 1") != std::string::npos ? "frame" : field("e");
      if (r.kind.empty()) fail("a line that is neither a frame nor an event");
    }
    out.push_back(std::move(r));
  }
  gzclose(f);
  if (out.empty()) throw core::UserError(path + ": empty recording");
  return out;
}

}  // namespace llsf::sim
