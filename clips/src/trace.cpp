// SPDX-License-Identifier: MIT
// The agent trace: the Tracer's events and their one-line text form (docs/clips.md, "Tracing").
#include "llsf/clips/trace.h"

#include <cstdio>

#include "llsf/clips/agent.h"
#include "tracer.h"

namespace llsf::clips {

std::string trace_prefix(core::SimTime time, std::string_view robot) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "[%7.2f] ", time.seconds());
  std::string out(buf);
  out.append(robot).append(" ");
  return out;
}

std::string trace_line(const TraceEvent& e) {
  using Kind = TraceEvent::Kind;
  if (e.kind == Kind::kCycleEnd) return {};
  std::string out = trace_prefix(e.time, e.agent);
  switch (e.kind) {
    case Kind::kFire: {
      out.append("FIRE ").append(e.name).append(" ");
      bool first = true;
      for (const std::int64_t i : e.facts) {
        out.append(first ? " f-" : ", f-").append(std::to_string(i));
        first = false;
        if (e.host != nullptr) {
          const std::string text = e.host->fact_text(i);
          if (!text.empty()) out.append(" ").append(text);
        }
      }
      break;
    }
    case Kind::kAssert:
    case Kind::kRetract:
      out.append(e.kind == Kind::kAssert ? "==> f-" : "<== f-")
          .append(std::to_string(e.fact))
          .append(" ")
          .append(e.text);
      break;
    case Kind::kMsgIn:
      out.append("msg <- ").append(e.peer).append(" ").append(e.name).append(" {");
      out.append(e.text).append("}");
      break;
    case Kind::kMsgOut:
      out.append("msg -> ").append(e.name).append(" {").append(e.text).append("}");
      break;
    case Kind::kLog:
      out.append("log ").append(to_string(e.level)).append(" ").append(e.text);
      break;
    case Kind::kCycleEnd:
      break;
  }
  strip_addresses(out);
  return out;
}

void strip_addresses(std::string& text) {
  static constexpr std::string_view kPointer = "<Pointer-C-";
  for (std::size_t p = text.find(kPointer); p != std::string::npos;
       p = text.find(kPointer, p + 1)) {
    const std::size_t end = text.find('>', p);
    if (end == std::string::npos) return;
    text.replace(p, end - p + 1, "<Pointer-C>");
  }
}

namespace detail {

TraceEvent Tracer::event(TraceEvent::Kind kind) const {
  TraceEvent e;
  e.kind = kind;
  e.time = state_.now;
  e.agent = state_.config.robot_name;
  e.host = host_;
  return e;
}

void Tracer::send(const TraceEvent& e) {
  if (!sink_) return;
  try {
    sink_(e);
  } catch (...) {  // a throwing sink loses the event, never the agent's cycle
  }
}

void Tracer::on_fire(std::string_view rule, std::span<const std::int64_t> facts) {
  TraceEvent e = event(TraceEvent::Kind::kFire);
  e.name = rule;
  e.facts = facts;
  send(e);
}

void Tracer::on_fact(bool asserted, std::int64_t index, std::string_view text) {
  TraceEvent e = event(asserted ? TraceEvent::Kind::kAssert : TraceEvent::Kind::kRetract);
  e.fact = index;
  e.text = text;
  send(e);
}

void Tracer::log(LogLevel level, std::string_view text) {
  if (!options_.log) return;
  TraceEvent e = event(TraceEvent::Kind::kLog);
  e.level = level;
  e.text = text;
  send(e);
}

void Tracer::message_in(const google::protobuf::Message& m, std::string_view from,
                        core::SimTime at) {
  if (!options_.messages) return;
  text_ = m.ShortDebugString();
  TraceEvent e = event(TraceEvent::Kind::kMsgIn);
  e.time = at;
  e.name = m.GetDescriptor()->name();
  e.peer = from;
  e.text = text_;
  send(e);
}

void Tracer::message_out(const google::protobuf::Message& m) {
  if (!options_.messages) return;
  text_ = m.ShortDebugString();
  TraceEvent e = event(TraceEvent::Kind::kMsgOut);
  e.name = m.GetDescriptor()->name();
  e.text = text_;
  send(e);
}

void Tracer::cycle_end() { send(event(TraceEvent::Kind::kCycleEnd)); }

}  // namespace detail
}  // namespace llsf::clips
