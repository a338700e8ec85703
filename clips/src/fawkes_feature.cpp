// SPDX-License-Identifier: MIT
// Fawkes feature: the feature facts of Fawkes' clips plugin ((ff-feature X) for what the host
// offers, (ff-feature-request "X") asserting (ff-feature-loaded X)) and the motor switch
// (motor-enable / motor-disable, Fawkes' clips-motor-switch). docs/fawkes.md.
#include <algorithm>
#include <array>

#include "feature.h"

namespace llsf::clips::detail {

std::span<const std::string_view> fawkes_features() {
  // What a Fawkes-style agent may request: the blackboard (the interfaces of
  // blackboard_feature.cpp), config-load, the pb-* functions, the motor switch.
  static constexpr std::array<std::string_view, 4> kFeatures = {"blackboard", "config",
                                                                "motor-switch", "protobuf"};
  return kFeatures;
}

namespace {

class FawkesFeature final : public Feature {
 public:
  explicit FawkesFeature(HostState& s) : s_(s) {}

  void define(Environment& env) override {
    // (ff-feature-request "name"): TRUE if the host offers the feature (asserting
    // (ff-feature-loaded name) the first time), FALSE with a warning if it does not.
    env.define_function("ff-feature-request", "11k", [this, &env](Args& a) {
      std::string_view name;
      a.text(0, name);
      const auto offered = fawkes_features();
      if (std::find(offered.begin(), offered.end(), name) == offered.end()) {
        s_.log(LogLevel::kWarn, "ff-feature-request: the host offers no feature " +
                                    std::string(name) + " (it offers " + offered_text() + ")");
        return Value::boolean(false);
      }
      if (std::find(loaded_.begin(), loaded_.end(), name) != loaded_.end()) {
        s_.log(LogLevel::kWarn,
               "ff-feature-request: feature " + std::string(name) + " requested again");
        return Value::boolean(true);
      }
      loaded_.emplace_back(name);
      env.assert_string("(ff-feature-loaded " + std::string(name) + ")");
      return Value::boolean(true);
    });
    env.define_function("motor-enable", "00", [this](Args&) {
      if (s_.io.motor) s_.io.motor(true);
      return Value{};
    });
    env.define_function("motor-disable", "00", [this](Args&) {
      if (s_.io.motor) s_.io.motor(false);
      return Value{};
    });
  }

  // The feature facts survive a (reset), as Fawkes meant them to (its deffacts; Fawkes issue
  // #310 fixed their construction in March 2014).
  void after_reset(Environment& env) override {
    if (!s_.config.fawkes) return;
    for (const std::string_view f : fawkes_features())
      env.assert_string("(ff-feature " + std::string(f) + ")");
    for (const std::string& f : loaded_) env.assert_string("(ff-feature-loaded " + f + ")");
  }

 private:
  static std::string offered_text() {
    std::string out;
    for (const std::string_view f : fawkes_features()) {
      if (!out.empty()) out += ", ";
      out.append(f);
    }
    return out;
  }

  HostState& s_;
  std::vector<std::string> loaded_;
};

}  // namespace

std::unique_ptr<Feature> make_fawkes_feature(HostState& s) {
  return std::make_unique<FawkesFeature>(s);
}

}  // namespace llsf::clips::detail
