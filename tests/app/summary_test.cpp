// SPDX-License-Identifier: MIT
// `llsfsim run`'s summary is made from the metric table (study/metrics.h): every metric's part
// is on its line with its value, absent ones say so, and lines without news are left out.
#include <doctest/doctest.h>
#include <fmt/format.h>

#include <sstream>
#include <string>

#include "../../app/src/commands.h"
#include "llsf/study/metrics.h"
#include "llsf/study/runner.h"

using namespace llsf;

namespace {

// The line of `text` that starts with `label` padded to 11 columns ("" if none).
std::string line_of(const std::string& text, std::string_view label) {
  const std::string start = fmt::format("{:<11}", label);
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) {
    if (l.starts_with(start)) return l;
  }
  return "";
}

}  // namespace

TEST_CASE("summary: every metric's part on its line, from the metric table") {
  study::RunResult r;
  r.scenario = "s";
  r.profile = "robotino-2013";
  r.game_time_s = 1080.0;
  r.points = 101;
  r.exploration_points = 37;
  r.deliveries = 7;
  r.products_p3 = 4;
  r.recycled = 5;
  r.recycle_points = 15;
  r.lock_grants = 13;
  r.lock_hold_max_s = 19.75;
  r.first_complex_production_s = 303.0;
  r.role_changes = 2;
  r.storage_min = 3;
  r.jams = 1;
  r.messages_sent = 26000;
  r.cpu_s = 28.5;
  r.real_time_factor = 37.9;
  r.orders.push_back({1, "P1", 3, 1, 0, 299});
  r.tests.push_back({"points", true, "101 points (need >= 30 points)", 1080.0});
  std::ostringstream out;
  app::print_summary(r, out);
  const std::string text = out.str();
  for (const study::Metric& m : study::metrics()) {
    CAPTURE(m.name);
    if (!m.summary_same_as.empty()) continue;  // shown through the metric it is a share of
    const std::string line = line_of(text, m.line);
    REQUIRE_FALSE(line.empty());
    const std::optional<double> v = m.value(r);
    const std::string part = !v ? std::string(m.summary_absent)
                             : m.json_form == study::JsonForm::kBool
                                 ? fmt::format(fmt::runtime(m.summary), *v != 0.0 ? "yes" : "no")
                                 : fmt::format(fmt::runtime(m.summary), *v);
    CHECK(line.find(part) != std::string::npos);
  }
  CHECK(line_of(text, "points") ==
        "points      101   exploration   37   production    0   (0 awards)");
  CHECK(line_of(text, "products") ==
        "products   P1 0  P2 0  P3 4   recycled 5 (15 points)   deliveries 7");
  CHECK(line_of(text, "production") ==
        "production first complex product at 303 s of production, 2 role changes, storage low "
        "3 pucks");
  CHECK(line_of(text, "profile").starts_with("profile    robotino-2013: 1 jams"));
  CHECK(text.find("           #1 P1 1/3 [0-299 s]\n") != std::string::npos);
  CHECK(text.find("test       PASS  points: 101 points") != std::string::npos);

  // Lines without news are left out: no locks, no orders, no tests, the ideal profile.
  study::RunResult quiet;
  quiet.profile = "ideal";
  std::ostringstream q;
  app::print_summary(quiet, q);
  for (const char* label : {"locks", "orders", "tests", "profile"}) {
    CAPTURE(label);
    CHECK(line_of(q.str(), label).empty());
  }
  CHECK(line_of(q.str(), "production").find("first complex product none") != std::string::npos);
}
