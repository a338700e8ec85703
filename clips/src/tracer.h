// SPDX-License-Identifier: MIT
// Tracer: an agent's trace (llsf/clips/trace.h) -- observes the environment's firings and fact
// changes and turns them, the messages and the log lines into TraceEvents for the sink.
#pragma once

#include <google/protobuf/message.h>

#include <string>
#include <string_view>

#include "environment.h"
#include "feature.h"
#include "llsf/clips/trace.h"

namespace llsf::clips::detail {

class Tracer final : public TraceObserver {
 public:
  /// `state` and `host` are borrowed and outlive the tracer.
  Tracer(const HostState& state, const AgentHost& host, TraceOptions options, TraceSink sink)
      : state_(state), host_(&host), options_(options), sink_(std::move(sink)) {}
  /// The host moved (AgentHost's move operations).
  void set_host(const AgentHost& host) { host_ = &host; }

  const TraceOptions& options() const { return options_; }

  void on_fire(std::string_view rule, std::span<const std::int64_t> facts) override;
  void on_fact(bool asserted, std::int64_t index, std::string_view text) override;
  void log(LogLevel level, std::string_view text);
  void message_in(const google::protobuf::Message& m, std::string_view from, core::SimTime at);
  void message_out(const google::protobuf::Message& m);
  void cycle_end();

 private:
  TraceEvent event(TraceEvent::Kind kind) const;
  void send(const TraceEvent& e);

  const HostState& state_;
  const AgentHost* host_;
  TraceOptions options_;
  TraceSink sink_;
  std::string text_;  // reused for message texts
};

}  // namespace llsf::clips::detail
