// SPDX-License-Identifier: MIT
// to_wire_time() / from_wire_time(): the absolute times of a message shifted by reflection.
#include "llsf/refbox/wire_time.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <limits>
#include <string_view>
#include <vector>

namespace llsf::refbox {

namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::Reflection;

constexpr std::int64_t kNsPerSec = 1000000000;

/// a + b, saturated at the int64 range.
std::int64_t saturated_add(std::int64_t a, std::int64_t b) {
  std::int64_t r = 0;
  if (!__builtin_add_overflow(a, b, &r)) return r;
  return b > 0 ? std::numeric_limits<std::int64_t>::max()
               : std::numeric_limits<std::int64_t>::min();
}

/// (sec, nsec) shifted by `delta_ns`; nsec stays in [0, 1e9) if it was.
void shift(std::int64_t& sec, std::int64_t& nsec, std::int64_t delta_ns) {
  std::int64_t dsec = delta_ns / kNsPerSec;
  std::int64_t dnsec = delta_ns % kNsPerSec;
  if (nsec >= 0 && nsec < kNsPerSec) {
    nsec += dnsec;
    if (nsec < 0) {
      nsec += kNsPerSec;
      dsec = saturated_add(dsec, -1);
    } else if (nsec >= kNsPerSec) {
      nsec -= kNsPerSec;
      dsec = saturated_add(dsec, 1);
    }
  }
  sec = saturated_add(sec, dsec);
}

/// Shifts a llsf_msgs.Time (fields sec = 1, nsec = 2) in place.
void shift_time(Message& t, std::int64_t delta_ns) {
  const Reflection& r = *t.GetReflection();
  const FieldDescriptor* s = t.GetDescriptor()->FindFieldByName("sec");
  const FieldDescriptor* n = t.GetDescriptor()->FindFieldByName("nsec");
  if (s == nullptr || n == nullptr || s->cpp_type() != FieldDescriptor::CPPTYPE_INT64 ||
      n->cpp_type() != FieldDescriptor::CPPTYPE_INT64) {
    return;
  }
  std::int64_t sec = r.GetInt64(t, s);
  std::int64_t nsec = r.GetInt64(t, n);
  shift(sec, nsec, delta_ns);
  r.SetInt64(&t, s, sec);
  r.SetInt64(&t, n, nsec);
}

void shift_message(Message& m, std::int64_t delta_ns) {
  const std::string& type = m.GetDescriptor()->full_name();
  const Reflection& r = *m.GetReflection();
  if (type == "llsf_log_msgs.LogMessage") {
    const FieldDescriptor* s = m.GetDescriptor()->FindFieldByName("ts_sec");
    const FieldDescriptor* n = m.GetDescriptor()->FindFieldByName("ts_nsec");
    if (s != nullptr && n != nullptr && s->cpp_type() == FieldDescriptor::CPPTYPE_INT64 &&
        n->cpp_type() == FieldDescriptor::CPPTYPE_INT64 && r.HasField(m, s)) {
      std::int64_t sec = r.GetInt64(m, s);
      std::int64_t nsec = r.GetInt64(m, n);
      shift(sec, nsec, delta_ns);
      r.SetInt64(&m, s, sec);
      r.SetInt64(&m, n, nsec);
    }
    return;
  }
  const bool game_state = type == "llsf_msgs.GameState";
  std::vector<const FieldDescriptor*> fields;
  r.ListFields(m, &fields);
  for (const FieldDescriptor* f : fields) {
    if (f->cpp_type() != FieldDescriptor::CPPTYPE_MESSAGE) continue;
    // GameState.game_time is the phase-relative game time, in 2013 as here.
    if (game_state && f->name() == "game_time") continue;
    const bool is_time = f->message_type()->full_name() == "llsf_msgs.Time";
    if (f->is_repeated()) {
      for (int i = 0; i < r.FieldSize(m, f); ++i) {
        Message& sub = *r.MutableRepeatedMessage(&m, f, i);
        if (is_time) {
          shift_time(sub, delta_ns);
        } else {
          shift_message(sub, delta_ns);
        }
      }
    } else {
      Message& sub = *r.MutableMessage(&m, f);
      if (is_time) {
        shift_time(sub, delta_ns);
      } else {
        shift_message(sub, delta_ns);
      }
    }
  }
}

}  // namespace

void to_wire_time(Message& msg, const WireClock& clock) { shift_message(msg, clock.offset_ns); }

void from_wire_time(Message& msg, const WireClock& clock) {
  shift_message(msg, clock.offset_ns == std::numeric_limits<std::int64_t>::min()
                         ? std::numeric_limits<std::int64_t>::max()
                         : -clock.offset_ns);
}

}  // namespace llsf::refbox
