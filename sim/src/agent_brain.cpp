// SPDX-License-Identifier: MIT
#include "llsf/sim/agent_brain.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <utility>

#include "llsf/clips/agent_files.h"
#include "llsf/core/input_file.h"

namespace llsf::sim {

std::vector<std::string> agent_files(const std::vector<std::string>& entries) {
  return clips::expand_agent_files(entries);
}

namespace {

clips::Value field_value(const lua::InterfaceField& f);

// A Fawkes-style agent's blackboard (docs/fawkes.md, "The blackboard"): the interface objects of
// the robot's skill engine, which llsfsim's sensors and actuators write; the agent reads,
// writes and sends messages to the same objects as the skills.
class SkillBlackboard final : public clips::Blackboard {
 public:
  explicit SkillBlackboard(lua::SkillEngine& engine) : engine_(engine) {}

  bool read(std::string_view type, std::string_view id, clips::InterfaceReading& out,
            std::string& error) override {
    lua::InterfaceSnapshot s = engine_.read_interface(type, id);
    if (!s.known) {
      error = std::move(s.error);
      return false;
    }
    out.has_writer = s.has_writer;
    out.robot_writer = s.robot_writer;
    out.written = s.written;
    out.fields.clear();
    for (const lua::InterfaceField& f : s.fields) out.fields.emplace_back(f.name, field_value(f));
    return true;
  }

  std::int64_t version() override { return engine_.blackboard_version(); }

  std::string write(std::string_view type, std::string_view id,
                    const clips::InterfaceFields& fields) override {
    return engine_.write_interface(type, id, lua_fields(fields));
  }

  std::int64_t send(std::string_view type, std::string_view id, std::string_view message,
                    const clips::InterfaceFields& fields, std::string& error) override {
    return engine_.send_interface_message(type, id, message, lua_fields(fields), error);
  }

 private:
  // CLIPS values as the Lua objects hold them: TRUE/FALSE booleans, other symbols (enums) and
  // strings as strings, numbers as numbers, multifields as arrays.
  static std::vector<lua::InterfaceField> lua_fields(const clips::InterfaceFields& fields) {
    using Kind = lua::InterfaceField::Kind;
    std::vector<lua::InterfaceField> out;
    for (const auto& [name, v] : fields) {
      lua::InterfaceField f;
      f.name = name;
      f.array = v.type == clips::Value::Type::kMultifield;
      const std::vector<clips::Value> one{v};
      const std::vector<clips::Value>& items = f.array ? v.items : one;
      bool first = true;
      for (const clips::Value& e : items) {
        Kind k = Kind::kSymbol;
        if (e.is_symbol("TRUE") || e.is_symbol("FALSE")) {
          k = Kind::kBool;
          f.numbers.push_back(e.text == "TRUE" ? 1.0 : 0.0);
        } else if (e.type == clips::Value::Type::kInteger) {
          k = Kind::kInteger;
          f.numbers.push_back(static_cast<double>(e.integer));
        } else if (e.type == clips::Value::Type::kFloat) {
          k = Kind::kFloat;
          f.numbers.push_back(e.real);
        } else {
          k = e.type == clips::Value::Type::kString ? Kind::kString : Kind::kSymbol;
          f.texts.push_back(e.text);
        }
        if (first) f.kind = k;
        first = false;
      }
      out.push_back(std::move(f));
    }
    return out;
  }

  lua::SkillEngine& engine_;
};

}  // namespace

AgentBrain::AgentBrain(Game& game, int index, AgentBrainConfig config, clips::LogSink log,
                       clips::LockListener locks, AgentReports reports) {
  skills_ = std::make_unique<SkillBrain>(game, index, std::move(config.skills));
  const RobotStack& stack = game.robot(index);
  clips::AgentConfig ac;
  ac.robot_name = std::string(stack.name());
  ac.robot_number = game.config().world.robots.at(static_cast<std::size_t>(index)).jersey_or(index);
  ac.team_name = !config.team.empty()          ? config.team
                 : !game.config().team.empty() ? game.config().team
                                               : game.config().refbox.team;
  core::RandomStream seed = game.rng().stream("clips/" + ac.robot_name);
  ac.seed = seed.next_u64();
  ac.max_rules_per_cycle = config.max_rules_per_cycle;
  max_runaway_cycles_ = config.max_runaway_cycles;
  start_ = config.start;
  ac.sandbox = config.sandbox;
  ac.fawkes = config.fawkes;
  ac.agent_dir = config.agent_dir;
  ac.config = std::move(config.config);
  if (config.locks) {
    ac.locks = true;
    ac.lock_config.team_size =
        config.lock_team_size > 0 ? config.lock_team_size : game.robot_count();
    std::erase_if(ac.config,
                  [](const clips::ConfigEntry& e) { return e.path == "/clips-agent/use-locks"; });
    ac.config.push_back(clips::ConfigEntry::of("/clips-agent/use-locks", true));
  }
  clips::AgentIo io;
  io.skills = this;
  io.messages = &game.registry();
  RobotRadio* radio = &game.robot(index).radio();
  io.broadcast = [radio](const google::protobuf::Message& m) { radio->broadcast(m); };
  // pb-send to the refbox (pb-connect's server): the radio has no unicast, the refbox hears
  // every broadcast (docs/fawkes.md).
  io.send = io.broadcast;
  RobotStack* robot = &game.robot(index);
  io.motor = [robot](bool on) { robot->set_motor_enabled(on); };
  if (config.fawkes) {
    blackboard_ = std::make_unique<SkillBlackboard>(skills_->engine());
    io.blackboard = blackboard_.get();
  }
  io.log = std::move(log);
  io.lock_events = std::move(locks);
  io.issues = std::move(reports.issues);
  io.events = std::move(reports.events);
  file_entries_ = std::move(config.agent_files);
  locks_ = config.locks;
  host_config_ = std::move(ac);
  host_io_ = std::move(io);
  loaded_ = stamp_files();
  agent_ = make_host();
}

std::unique_ptr<clips::AgentHost> AgentBrain::make_host() const {
  auto host = std::make_unique<clips::AgentHost>(host_config_, host_io_);
  for (const std::string& f : agent_files(file_entries_)) {
    try {
      host->load_file(f);
    } catch (const clips::AgentLoadError& e) {
      // The lock template exists only with the lock protocol on: name the switch.
      const std::string what = e.what();
      std::string error;
      const std::string text =
          core::try_read_input_file(f, core::kMaxSourceBytes, "CLIPS file", error).value_or("");
      if (!locks_ && !host_config_.fawkes &&
          (what.find("deftemplate lock") != std::string::npos ||
           text.find("(lock (") != std::string::npos)) {
        throw clips::AgentLoadError(
            what +
            "\nhint: the agent uses the host's lock facts, which exist only with the lock "
            "protocol on: set `robots.locks: true` in the scenario (docs/locks.md)");
      }
      throw;
    }
  }
  return host;
}

std::vector<AgentBrain::FileStamp> AgentBrain::stamp_files() const {
  std::vector<FileStamp> out;
  for (const std::string& f : agent_files(file_entries_)) {
    FileStamp s{f, -1, 0};
    std::error_code ec;
    const auto t = std::filesystem::last_write_time(f, ec);
    if (!ec)
      s.mtime_ns =
          std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
    const auto size = std::filesystem::file_size(f, ec);
    if (!ec) s.size = size;
    out.push_back(std::move(s));
  }
  return out;
}

AgentBrain::Reload AgentBrain::reload_if_changed() {
  Reload r;
  std::vector<FileStamp> now = stamp_files();
  if (now == loaded_) return r;
  r.changed = true;
  // Name the first file that differs (or the one that appeared or went).
  std::string which;
  for (std::size_t i = 0; i < std::max(now.size(), loaded_.size()) && which.empty(); ++i) {
    if (i >= now.size())
      which = loaded_[i].path + " removed";
    else if (i >= loaded_.size())
      which = now[i].path + " added";
    else if (!(now[i] == loaded_[i]))
      which = now[i].path + " changed";
  }
  loaded_ = std::move(now);  // a broken file is reported once, not at every check
  try {
    std::unique_ptr<clips::AgentHost> fresh = make_host();
    skills_->engine().stop();
    errors_before_reload_ += agent_->runtime_errors();
    agent_ = std::move(fresh);
    if (trace_sink_) agent_->set_trace(trace_options_, trace_sink_);
    // New rules: a halted agent gets another chance.
    rule_loops_ = budget_stops_ = 0;
    halt_.reset();
    r.reloaded = true;
    r.text = "agent reloaded (" + which + "); it restarts with its new rules";
  } catch (const clips::AgentLoadError& e) {
    r.text = "agent not reloaded (" + which + "), the old one goes on: " + e.what();
  }
  return r;
}

AgentBrain::~AgentBrain() = default;

void AgentBrain::set_trace(clips::TraceOptions options, clips::TraceSink sink) {
  trace_options_ = options;
  trace_sink_ = sink;
  agent_->set_trace(options, std::move(sink));
}

void AgentBrain::on_skill_cycle(lua::RobotApi& robot) { skills_->on_skill_cycle(robot); }

namespace {

const char* lamp_symbol(lua::Lamp l) {
  switch (l) {
    case lua::Lamp::kOn:
      return "ON";
    case lua::Lamp::kBlink:
      return "BLINKING";
    case lua::Lamp::kOff:
      return "OFF";
  }
  return "UNKNOWN";
}

clips::Value field_value(const lua::InterfaceField& f) {
  using Kind = lua::InterfaceField::Kind;
  const auto element = [&f](std::size_t i) {
    switch (f.kind) {
      case Kind::kString:
        return clips::Value::string(f.texts[i]);
      case Kind::kInteger:
        return clips::Value::integer_value(static_cast<std::int64_t>(f.numbers[i]));
      case Kind::kFloat:
        return clips::Value::float_value(f.numbers[i]);
      case Kind::kBool:
        return clips::Value::boolean(f.numbers[i] != 0.0);
      case Kind::kSymbol:
        break;
    }
    return clips::Value::symbol(f.texts[i]);
  };
  const std::size_t n =
      f.kind == Kind::kSymbol || f.kind == Kind::kString ? f.texts.size() : f.numbers.size();
  if (!f.array) return n > 0 ? element(0) : clips::Value{};
  std::vector<clips::Value> items;
  for (std::size_t i = 0; i < n; ++i) items.push_back(element(i));
  return clips::Value::multifield(std::move(items));
}

}  // namespace

void AgentBrain::on_agent_cycle(lua::RobotApi& robot, RobotRadio& radio) {
  if (halt_) return;                 // halted: no cycle (the game clears the inbox)
  if (robot.now() < start_) return;  // not switched on yet
  const lua::PoseEstimate pose = robot.pose();
  if (pose.valid) agent_->set_pose(pose.pose);
  if (host_config_.fawkes) {
    // The light detection as Fawkes' light plugin wrote RobotinoLightInterface "Light_State"
    // (docs/fawkes.md): the lamps (UNKNOWN while no device is seen), ready while one is, and
    // visibility_history in frames of the skill rate since the reading last changed (negative:
    // since the device was lost), as the skills' interface of that id counts them.
    const lua::LightReading light = robot.light();
    const core::SimTime now = robot.now();
    if (light.visible != light_seen_ && !light.visible) light_lost_since_ = now;
    light_seen_ = light.visible;
    const std::int64_t frame_ns = skills_->engine().cycle_period().ns();
    const std::int64_t since_ns =
        (now - (light.visible ? light.stable_since : light_lost_since_)).ns();
    const std::int64_t frames =
        (frame_ns > 0 ? std::max<std::int64_t>(since_ns, 0) / frame_ns : 0) + 1;
    using clips::Value;
    if (light_fields_.empty()) {
      light_fields_ = {{"red", Value::symbol("")},
                       {"yellow", Value::symbol("")},
                       {"green", Value::symbol("")},
                       {"visibility_history", Value::integer_value(0)},
                       {"ready", Value::boolean(false)}};
    }
    // (the same values as made afresh: only the symbols' texts and the integer change)
    light_fields_[0].second.text = light.visible ? lamp_symbol(light.red) : "UNKNOWN";
    light_fields_[1].second.text = light.visible ? lamp_symbol(light.yellow) : "UNKNOWN";
    light_fields_[2].second.text = light.visible ? lamp_symbol(light.green) : "UNKNOWN";
    light_fields_[3].second.integer = light.visible ? frames : -frames;
    light_fields_[4].second.text = light.visible ? "TRUE" : "FALSE";
    agent_->write_interface("RobotinoLightInterface", "Light_State", light_fields_);
    // What the skills wrote with Fawkes' API (the team's "Light determined"): one blackboard.
    for (const lua::WrittenInterface& w : skills_->engine().written_interfaces()) {
      std::vector<std::pair<std::string, Value>> fields;
      for (const lua::InterfaceField& f : w.fields) fields.emplace_back(f.name, field_value(f));
      agent_->write_interface(w.type, w.id, std::move(fields));
    }
  }
  for (Received& r : radio.inbox()) {
    if (r.message) agent_->receive(std::move(r.message), r.from, r.from_id, r.at);
  }
  const clips::CycleResult c = agent_->cycle(robot.now());
  // A runaway agent is halted after a bounded number of runaway cycles: each costs a whole
  // budget of CPU (10,000 firings or 10^6 steps), and the game would crawl on for hours.
  if (c.limit_reached) ++rule_loops_;
  if (c.budget_exceeded) ++budget_stops_;
  if (max_runaway_cycles_ <= 0 || rule_loops_ + budget_stops_ < max_runaway_cycles_) return;
  skills_->engine().stop();  // aborts the skill string and stops the robot
  Halt h;
  h.time = robot.now();
  h.rule_loops = rule_loops_;
  h.budget_stops = budget_stops_;
  h.text = "agent halted after " + std::to_string(rule_loops_ + budget_stops_) +
           " runaway cycles (" + std::to_string(rule_loops_) + " cut by the rule firing limit, " +
           std::to_string(budget_stops_) +
           " stopped by the work budget; the issues before name the rules): it cycles no more "
           "and the robot stops for the rest of the game";
  halt_ = std::move(h);
}

void AgentBrain::exec(std::string_view skill_string) { skills_->exec(skill_string); }
void AgentBrain::stop() { skills_->engine().stop(); }

clips::SkillStatus AgentBrain::status() const {
  switch (skills_->engine().status()) {
    case lua::SkillStatus::kInactive:
      return clips::SkillStatus::kIdle;
    case lua::SkillStatus::kRunning:
      return clips::SkillStatus::kRunning;
    case lua::SkillStatus::kFinal:
      return clips::SkillStatus::kFinal;
    case lua::SkillStatus::kFailed:
      return clips::SkillStatus::kFailed;
  }
  return clips::SkillStatus::kIdle;
}
std::string AgentBrain::error() const { return skills_->engine().error(); }
std::string AgentBrain::skill_string() const { return skills_->engine().skill_string(); }
std::string AgentBrain::result() const { return skills_->engine().result(); }

}  // namespace llsf::sim
