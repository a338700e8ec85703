// SPDX-License-Identifier: MIT
// The installed interface (llsfsim/llsfsim.h) on study's scenario loader and game runner.
#include "llsfsim/llsfsim.h"

#include <optional>
#include <sstream>
#include <utility>

#include "llsf/core/error.h"
#include "llsf/core/sim_time.h"
#include "llsf/core/version.h"
#include "llsf/study/metrics.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"

namespace llsfsim {

struct Scenario::Impl {
  llsf::study::Scenario scenario;
};

namespace {

// Runs `body`, turning the library's bad-input errors into Error (what() unchanged).
template <typename F>
auto translate(F&& body) {
  try {
    return std::forward<F>(body)();
  } catch (const llsf::core::UserError& e) {
    throw Error(e.what());
  }
}

}  // namespace

std::string version() { return std::string(llsf::core::kVersion); }

Scenario::Scenario(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

std::vector<Scenario> Scenario::load(const std::string& file) {
  return translate([&] {
    llsf::study::ScenarioFile f = llsf::study::load_scenario(file);
    std::vector<Scenario> out;
    out.reserve(f.variants.size());
    for (llsf::study::Scenario& s : f.variants) {
      out.emplace_back(std::make_shared<const Impl>(Impl{std::move(s)}));
    }
    return out;
  });
}

std::string Scenario::name() const { return impl_->scenario.name; }
std::string Scenario::variant() const { return impl_->scenario.variant; }
std::vector<std::uint64_t> Scenario::seeds() const { return impl_->scenario.seeds; }
double Scenario::duration_s() const { return impl_->scenario.duration.seconds(); }

void Scenario::set_duration_s(double seconds) {
  using Limits = llsf::study::ScenarioLimits;
  if (!(seconds >= Limits::kMinDurationS && seconds <= Limits::kMaxDurationS)) {
    std::ostringstream message;
    message << "set_duration_s: " << seconds << " s is outside [" << Limits::kMinDurationS << ", "
            << Limits::kMaxDurationS << "] s (the scenario limits)";
    throw Error(message.str());
  }
  auto copy = std::make_shared<Impl>(*impl_);
  copy->scenario.duration = llsf::core::SimTime::from_sec(seconds);
  impl_ = std::move(copy);
}

Result play(const Scenario& scenario, std::uint64_t seed, const PlayOptions& options) {
  return translate([&] {
    llsf::study::RunHooks hooks;
    hooks.record_path = options.record_path;
    const llsf::study::RunResult r = llsf::study::run_game(scenario.impl_->scenario, seed, hooks);
    Result out;
    out.points = r.points;
    out.game_time_s = r.game_time_s;
    out.hash = r.result_hash;
    out.passed = r.passed();
    for (const llsf::study::Metric& m : llsf::study::metrics()) {
      if (const std::optional<double> v = m.value(r))
        out.statistics.emplace(std::string(m.name), *v);
    }
    for (const llsf::study::TestVerdict& t : r.tests) {
      out.tests.push_back({t.name, t.passed, t.detail});
    }
    out.json = llsf::study::to_json(r);
    return out;
  });
}

Result play(const Scenario& scenario, std::uint64_t seed) { return play(scenario, seed, {}); }

}  // namespace llsfsim
