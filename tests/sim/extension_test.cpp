// SPDX-License-Identifier: MIT
// Game extensions (extension.h): the Game calls every hook at its fixed point of the tick, in the
// documented order (docs/architecture.md "One tick"), an extension's setup changes the world the
// game is built from, its add-on reaches the robots' skill API, and callers find it by type.
#include "llsf/sim/extension.h"

#include <doctest/doctest.h>

#include <memory>
#include <string>
#include <vector>

#include "fixture.h"
#include "llsf/core/error.h"
#include "llsf/sim/game.h"
#include "llsf/sim/hackathon_extension.h"

using namespace llsf;
using namespace llsf::sim;

namespace {

/// One call of a hook or a brain: what, at which tick time, and the world's time then.
struct Call {
  std::string what;
  std::int64_t now_ns = 0;
  std::int64_t world_ns = 0;
};

/// Counts its hooks, logs them, adds a box (of a size drawn from its own stream) to the world and
/// gives robot 0 one coloured sighting per tick, named after the number of sense() calls.
class CountingExtension final : public GameExtension {
 public:
  CountingExtension(std::vector<Call>* log, bool add_box) : log_(log), add_box_(add_box) {}
  std::string_view name() const override { return "counting"; }

  void setup(GameConfig& config, const core::Rng& rng) override {
    ++setups;
    core::RandomStream s = rng.stream("test/counting");
    box_size_m = s.uniform(0.1, 0.2);
    if (!add_box_) return;
    // The place of the hackathon's first default box: free on the 2013 field.
    kinematic::ObstacleConfig box = HackathonConfig::default_obstacles().front();
    box.name = "counting_box";
    box.size_x_m = box.size_y_m = box_size_m;
    config.world.obstacles.push_back(box);
  }
  void on_built(Game& game) override {
    ++builts;
    robots_at_build = game.robot_count();
  }
  void pre_step(Game& game, SimTime now) override {
    ++pre_steps;
    log_->push_back({"pre", now.ns(), game.world().time().ns()});
  }
  void sense(Game& game, SimTime now) override {
    ++senses;
    log_->push_back({"sense", now.ns(), game.world().time().ns()});
    add_on_.sighting[0].colour = std::to_string(senses);
  }
  void post_step(Game& game, SimTime now) override {
    ++post_steps;
    ticks_at_post = game.ticks();
    log_->push_back({"post", now.ns(), game.world().time().ns()});
  }
  const RobotAddOn* robot_add_on(int robot) const override {
    return robot == 0 ? &add_on_ : nullptr;
  }

  int setups = 0, builts = 0, pre_steps = 0, senses = 0, post_steps = 0;
  int robots_at_build = 0;
  std::int64_t ticks_at_post = 0;
  double box_size_m = 0.0;

 private:
  struct AddOn final : RobotAddOn {
    std::span<const lua::ColourPuckSighting> colour_pucks() const override { return sighting; }
    std::vector<lua::ColourPuckSighting> sighting = std::vector<lua::ColourPuckSighting>(1);
  };
  std::vector<Call>* log_;
  bool add_box_;
  AddOn add_on_;
};

class CountingFactory final : public GameExtensionFactory {
 public:
  /// `add_box`: setup() adds its box; `reject`: validate() throws.
  explicit CountingFactory(std::vector<Call>* log, bool add_box = true, bool reject = false)
      : log_(log), add_box_(add_box), reject_(reject) {}
  void validate(const GameConfig& config) const override {
    (void)config;
    if (reject_) throw core::ConfigError("game.counting.rate: must be positive (got 0)");
  }
  std::unique_ptr<GameExtension> make() const override {
    return std::make_unique<CountingExtension>(log_, add_box_);
  }

 private:
  std::vector<Call>* log_;
  bool add_box_;
  bool reject_;
};

/// Logs the skill and agent cycles and what the skill API shows of the extension then.
struct LoggingBrain final : RobotBrain {
  LoggingBrain(const Game& g, std::vector<Call>* l) : game(g), log(l) {}
  void on_skill_cycle(lua::RobotApi& robot) override {
    log->push_back({"skill", robot.now().ns(), game.world().time().ns()});
    const auto seen = robot.colour_pucks();
    seen_colour = seen.empty() ? "" : seen[0].colour;
  }
  void on_agent_cycle(lua::RobotApi& robot, RobotRadio& radio) override {
    (void)radio;
    log->push_back({"agent", robot.now().ns(), game.world().time().ns()});
  }
  const Game& game;
  std::vector<Call>* log;
  std::string seen_colour;
};

}  // namespace

TEST_CASE("game extension: every hook at its point of the tick, in order") {
  std::vector<Call> log;
  GameConfig c = test::small_game(2, 3);
  c.extensions.push_back(std::make_shared<CountingFactory>(&log));
  Game game(c);
  CountingExtension* ext = game.extension<CountingExtension>();
  REQUIRE(ext != nullptr);
  CHECK(game.extension_count() == 1);
  CHECK(game.extension<HackathonExtension>() == nullptr);
  CHECK(ext->setups == 1);
  CHECK(ext->builts == 1);
  CHECK(ext->robots_at_build == 2);
  CHECK(ext->pre_steps == 0);

  LoggingBrain brain(game, &log);
  game.set_brain(0, &brain);
  game.set_tick_hook([&](const Game& g) {
    log.push_back({"hook", g.time().ns(), g.world().time().ns()});
  });
  const std::int64_t dt = c.world.physics.step.ns();
  for (int tick = 1; tick <= 40; ++tick) {
    log.clear();
    game.step();
    const std::int64_t now = dt * tick;
    // Every hook once a tick; post_step sees the tick counted.
    CHECK(ext->pre_steps == tick);
    CHECK(ext->senses == tick);
    CHECK(ext->post_steps == tick);
    CHECK(ext->ticks_at_post == tick);
    // pre_step before the world steps, sense after it, then skills, agents, post_step, hook.
    std::vector<std::string> order;
    for (const Call& call : log) {
      order.push_back(call.what);
      CHECK(call.now_ns == now);
      CHECK(call.world_ns == (call.what == "pre" ? now - dt : now));
    }
    REQUIRE(order.size() >= 4);
    CHECK(order.front() == "pre");
    CHECK(order[1] == "sense");
    CHECK(order[order.size() - 2] == "post");
    CHECK(order.back() == "hook");
    if (order.size() == 6) {  // a tick with both cycles (the first one is)
      CHECK(order[2] == "skill");
      CHECK(order[3] == "agent");
    }
    if (tick == 1) CHECK(order.size() == 6);
    // The skill cycle of this tick saw this tick's sense() through the add-on.
    if (order.size() >= 5 && order[2] == "skill") CHECK(brain.seen_colour == std::to_string(tick));
  }
  game.set_brain(0, nullptr);
}

TEST_CASE("game extension: setup changes the world from its own stream; add-ons; config errors") {
  std::vector<Call> log;
  GameConfig c = test::small_game(2, 3);
  const std::size_t boxes = c.world.obstacles.size();
  c.extensions.push_back(std::make_shared<CountingFactory>(&log));
  const Game a(c);
  const Game b(c);
  const CountingExtension* ea = a.extension<CountingExtension>();
  REQUIRE(ea != nullptr);
  // The box is in the config the game plays, its size drawn from the seed's stream.
  REQUIRE(a.config().world.obstacles.size() == boxes + 1);
  CHECK(a.config().world.obstacles.back().name == "counting_box");
  CHECK(a.config().world.obstacles.back().size_x_m == ea->box_size_m);
  CHECK(ea->box_size_m >= 0.1);
  CHECK(ea->box_size_m < 0.2);
  CHECK(b.extension<CountingExtension>()->box_size_m == ea->box_size_m);
  CHECK(prepare_game_config(c).world.obstacles.size() == boxes + 1);
  // Each game has its own extension object.
  CHECK(b.extension<CountingExtension>() != ea);
  // The add-on reaches robot 0's skill API only.
  CHECK(a.robot(0).add_on() != nullptr);
  CHECK(a.robot(1).add_on() == nullptr);
  CHECK(a.robot(1).colour_pucks().empty());
  CHECK(a.robot(1).rescue() == nullptr);

  // Two extensions giving the same robot skill interfaces: an error naming both.
  GameConfig twice = c;
  twice.extensions.push_back(std::make_shared<CountingFactory>(&log, false));
  CHECK_THROWS_WITH_AS(Game{twice}, doctest::Contains("counting and counting both give robot1"),
                       core::ConfigError);
  // A factory's validate() is the game config's.
  GameConfig bad = test::small_game(1, 3);
  bad.extensions.push_back(std::make_shared<CountingFactory>(&log, true, true));
  CHECK_THROWS_WITH_AS(bad.validate(), doctest::Contains("game.counting.rate"), core::ConfigError);
  CHECK_THROWS_WITH_AS(Game{bad}, doctest::Contains("game.counting.rate"), core::ConfigError);
}

TEST_CASE("game extension: the hackathon world is one, found by type") {
  GameConfig c = test::small_game(2, 5);
  set_hackathon(c, HackathonConfig{});
  std::vector<Call> log;
  c.extensions.push_back(std::make_shared<CountingFactory>(&log, false));
  // The counting extension gives robot 0 interfaces as the hackathon does: refused.
  CHECK_THROWS_WITH_AS(Game{c}, doctest::Contains("hackathon and counting both give robot1"),
                       core::ConfigError);
  c.extensions.pop_back();
  // set_hackathon replaces the variant in its place; hackathon_config reads it back.
  HackathonConfig seven;
  seven.points_per_puck = 7;
  set_hackathon(c, seven);
  REQUIRE(c.extensions.size() == 1);
  REQUIRE(hackathon_config(c) != nullptr);
  CHECK(hackathon_config(c)->points_per_puck == 7);
  CHECK(hackathon_config(test::small_game(1)) == nullptr);
  Game game(c);
  const HackathonExtension* h = game.extension<HackathonExtension>();
  REQUIRE(h != nullptr);
  CHECK(h == hackathon_of(game));
  CHECK(h->config().points_per_puck == 7);
  CHECK(game.extension_count() == 1);
  for (int i = 0; i < game.robot_count(); ++i) {
    CHECK(game.robot(i).add_on() != nullptr);
    REQUIRE(game.robot(i).rescue() != nullptr);
    CHECK(game.robot(i).rescue()->safe_place == "SAFE");
  }
  // Its camera takes frames in tick step 6 (10 Hz: the first at the first tick).
  CHECK(h->camera(0).frames() == 0);
  game.step();
  CHECK(h->camera(0).frames() == 1);
  CHECK(hackathon_score(game)->rescuable == 9);
}
