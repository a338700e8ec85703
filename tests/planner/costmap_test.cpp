// SPDX-License-Identifier: MIT
// The move_base-2013 costmap's laser update against a plain reference: every beam walked cell
// by cell with the textbook Bresenham line (costmap_2d's raytraceLine), the hits marked, the
// robot's circle cleared. Costmap::update tests beams against the obstacle cells instead of
// walking them (planner/src/costmap.cpp: only the obstacle cells in a line's octant and slope bin),
// and, when it knows the beams' directions, only the beams that pass near an obstacle cell; the
// cells it leaves must be the same. Costs: every
// obstacle cell's inflation kernel (costmap_2d's cost of a distance) maxed over the whole grid;
// Costmap::inflate recomputes only the cells a changed obstacle reaches.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "llsf/planner/move_base.h"

using namespace llsf;
using llsf::core::Vec2;
using planner::Costmap;
using planner::MoveBaseConfig;

namespace {

// The reference: obstacle cells as a plain grid, updated as costmap_2d describes it.
struct Reference {
  Vec2 origin;
  int nx, ny;
  double res;
  double range;
  std::vector<std::uint8_t> obstacle;

  bool to_cell(const Vec2& p, int& i, int& j) const {
    const double fx = (p.x() - origin.x()) / res;
    const double fy = (p.y() - origin.y()) / res;
    if (!(fx >= 0.0 && fy >= 0.0)) return false;
    i = static_cast<int>(fx);
    j = static_cast<int>(fy);
    return i < nx && j < ny;
  }
  std::uint8_t& at(int i, int j) { return obstacle[static_cast<std::size_t>(j * nx + i)]; }

  // A rolling window's move: the origin by whole cells so that `center` is in the middle, the
  // cells that stay kept, the others free.
  void recenter(const Vec2& center) {
    const Vec2 wanted(center.x() - 0.5 * nx * res, center.y() - 0.5 * ny * res);
    const int si = static_cast<int>(std::floor((wanted.x() - origin.x()) / res));
    const int sj = static_cast<int>(std::floor((wanted.y() - origin.y()) / res));
    std::vector<std::uint8_t> moved(obstacle.size(), 0);
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const int oi = i + si, oj = j + sj;
        if (oi >= 0 && oj >= 0 && oi < nx && oj < ny) {
          moved[static_cast<std::size_t>(j * nx + i)] = at(oi, oj);
        }
      }
    }
    obstacle = moved;
    origin = Vec2(origin.x() + si * res, origin.y() + sj * res);
  }

  void update(const Vec2& from, const std::vector<Vec2>& hits, const Vec2& robot, double r) {
    int i0 = 0, j0 = 0;
    const int max_cells = static_cast<int>(range / res);
    if (to_cell(from, i0, j0)) {
      for (const Vec2& h : hits) {
        // The end clipped to the grid along the beam, as the costmap does it.
        Vec2 e = h;
        const Vec2 d = e - from;
        double t = 1.0;
        const double x_hi = origin.x() + nx * res - 1e-9, y_hi = origin.y() + ny * res - 1e-9;
        if (e.x() < origin.x()) t = std::min(t, (origin.x() - from.x()) / d.x());
        if (e.x() > x_hi) t = std::min(t, (x_hi - from.x()) / d.x());
        if (e.y() < origin.y()) t = std::min(t, (origin.y() - from.y()) / d.y());
        if (e.y() > y_hi) t = std::min(t, (y_hi - from.y()) / d.y());
        e = from + d * t;
        int i1 = 0, j1 = 0;
        if (!to_cell(e, i1, j1)) continue;
        int x = i0, y = j0;
        const int dx = std::abs(i1 - i0), dy = std::abs(j1 - j0);
        const int sx = i1 >= i0 ? 1 : -1, sy = j1 >= j0 ? 1 : -1;
        const int steps = std::min(std::max(dx, dy), max_cells);
        int err = dx - dy;
        for (int s = 0; s < steps; ++s) {
          at(x, y) = 0;
          const int e2 = 2 * err;
          if (e2 > -dy) {
            err -= dy;
            x += sx;
          }
          if (e2 < dx) {
            err += dx;
            y += sy;
          }
        }
      }
    }
    for (const Vec2& h : hits) {
      if ((h - from).squaredNorm() >= range * range) continue;
      int i = 0, j = 0;
      if (to_cell(h, i, j)) at(i, j) = 1;
    }
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const Vec2 c(origin.x() + (i + 0.5) * res, origin.y() + (j + 0.5) * res);
        if ((c - robot).squaredNorm() <= r * r) at(i, j) = 0;
      }
    }
  }

  // The inflated costs of the whole grid, from nothing (no static layer here).
  std::vector<std::uint8_t> costs(const MoveBaseConfig& c) const {
    std::vector<std::uint8_t> out(obstacle.size(), Costmap::kFree);
    const int inscribed = static_cast<int>(std::ceil(c.robot_radius_m / res - 1e-9));
    const int reach = static_cast<int>(std::ceil(c.inflation_radius_m / res - 1e-9));
    for (int b = 0; b < ny; ++b) {
      for (int a = 0; a < nx; ++a) {
        if (obstacle[static_cast<std::size_t>(b * nx + a)] == 0) continue;
        for (int j = std::max(0, b - reach); j <= std::min(ny - 1, b + reach); ++j) {
          for (int i = std::max(0, a - reach); i <= std::min(nx - 1, a + reach); ++i) {
            const double d = std::hypot(double(i - a), double(j - b));
            if (d > reach) continue;
            const auto cost =
                d == 0.0 ? Costmap::kLethal
                : d <= inscribed
                    ? Costmap::kInscribed
                    : static_cast<std::uint8_t>(
                          (Costmap::kInscribed - 1) *
                          std::exp(-c.cost_scaling_factor * (d * res - c.robot_radius_m)));
            std::uint8_t& o = out[static_cast<std::size_t>(j * nx + i)];
            o = std::max(o, cost);
          }
        }
      }
    }
    return out;
  }
};

// How the scans tell the costmap their beams' directions.
enum class Directions {
  kUnknown,  // hits only: every beam is tested
  kFull,     // a 360 degree scanner, some beams without a hit
  kPartial,  // a 240 degree scanner (as the Hokuyo URG-04LX), some beams without a hit
};

// What the beams hit.
enum class Scene {
  kScattered,  // random ranges: obstacle cells in every direction
  kDiscs,      // four discs (robots) that move a little between scans, elsewhere far ranges:
               // obstacle cells in a few directions, as in a game
};

// `scans` random scans of `beams` beams from random origins, some reaching past the grid; with
// `rolling`, the window first moves by up to two cells to have the scan's origin in its middle
// (as the local costmap rolls with the robot).
void compare(double res, int nx, int ny, int scans, int beams, std::uint32_t seed,
             bool rolling = false, Directions directions = Directions::kFull,
             Scene scene = Scene::kScattered) {
  const MoveBaseConfig config;
  const Vec2 origin(0.37, -0.21);
  Costmap costmap(origin, nx, ny, res, config);
  Reference ref{origin,
                nx,
                ny,
                res,
                config.raytrace_range_m,
                std::vector<std::uint8_t>(static_cast<std::size_t>(nx * ny), 0)};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double w = nx * res, h = ny * res;
  struct Disc {
    Vec2 c;
    double r;
  };
  std::vector<Disc> discs;
  for (int k = 0; k < 4; ++k) {
    discs.push_back({origin + Vec2(u(rng) * w, u(rng) * h), 0.15 + 0.2 * u(rng)});
  }
  int cleared = 0, marked = 0, costs_changed = 0;
  std::size_t tested = 0, offered = 0;
  std::vector<std::uint8_t> costs_before(static_cast<std::size_t>(nx * ny), Costmap::kFree);
  for (int scan = 0; scan < scans; ++scan) {
    // Origins mostly inside, now and then outside the grid; a rolling window's near its middle.
    Vec2 from(origin.x() + (u(rng) * 1.2 - 0.1) * w, origin.y() + (u(rng) * 1.2 - 0.1) * h);
    if (rolling) {
      from = ref.origin +
             Vec2(0.5 * w + (u(rng) * 4.0 - 2.0) * res, 0.5 * h + (u(rng) * 4.0 - 2.0) * res);
      costmap.recenter(from);
      ref.recenter(from);
      REQUIRE(costmap.origin().x() == ref.origin.x());
      REQUIRE(costmap.origin().y() == ref.origin.y());
    }
    std::vector<Vec2> hits;
    std::vector<int> of_hit;
    // The first beam's direction anywhere, also beyond +-pi (an unnormalised heading).
    const double first = (u(rng) * 2.0 - 1.0) * 7.0;
    const double fan = directions == Directions::kPartial ? 4.18879020478639 : 6.283185307179586;
    const double increment = fan / beams;
    for (Disc& d : discs) d.c += Vec2(u(rng) * 0.2 - 0.1, u(rng) * 0.2 - 0.1);
    for (int b = 0; b < beams; ++b) {
      const double a = first + increment * b;
      // Ranges: some short (marks near the robot), some past the raytrace range or the grid;
      // with known directions some beams see nothing (no hit).
      double range = u(rng) < 0.3 ? 0.2 + u(rng) * 1.0 : 0.5 + u(rng) * 5.0;
      if (scene == Scene::kDiscs) {
        range = 2.5 + u(rng) * 3.5;  // far, unless a disc is nearer
        const Vec2 dir(std::cos(a), std::sin(a));
        for (const Disc& d : discs) {
          const Vec2 m = d.c - from;
          const double p = dir.dot(m), q = m.squaredNorm() - d.r * d.r;
          if (q <= 0.0 || p * p < q) continue;  // inside it, or missed
          const double t = p - std::sqrt(p * p - q);
          if (t > 0.0) range = std::min(range, t);
        }
      }
      if (directions != Directions::kUnknown && u(rng) < 0.1) continue;
      hits.emplace_back(from.x() + range * std::cos(a), from.y() + range * std::sin(a));
      of_hit.push_back(b);
    }
    Costmap::Beams known;
    if (directions != Directions::kUnknown) known = {first, increment, beams, of_hit};
    const std::vector<std::uint8_t> before = ref.obstacle;  // (after the move)
    costmap.update(from, hits, known, from, 0.1);
    if (costmap.beams_tested() > 0) {  // (0: no obstacle cell in reach, or from outside)
      if (directions == Directions::kUnknown) REQUIRE(costmap.beams_tested() == hits.size());
      tested += costmap.beams_tested();
      offered += hits.size();
    }
    ref.update(from, hits, from, 0.1);
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const bool want = ref.at(i, j) != 0;
        if (costmap.obstacle(i, j) != want) {
          FAIL_CHECK("scan " << scan << " cell " << i << "," << j << ": reference " << want);
          return;
        }
        const bool was = before[static_cast<std::size_t>(j * nx + i)] != 0;
        cleared += (was && !want) ? 1 : 0;
        marked += (!was && want) ? 1 : 0;
      }
    }
    const std::vector<std::uint8_t> costs = ref.costs(config);
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const std::uint8_t want = costs[static_cast<std::size_t>(j * nx + i)];
        if (costmap.cost(i, j) != want) {
          FAIL_CHECK("scan " << scan << " cell " << i << "," << j << ": cost "
                             << int(costmap.cost(i, j)) << ", reference " << int(want));
          return;
        }
      }
    }
    costs_changed += costs != costs_before ? 1 : 0;
    costs_before = costs;
  }
  // The comparison saw both kinds of change.
  // (Discs change fewer cells: a few surfaces, not every direction.)
  const bool in_scene = scene == Scene::kDiscs;
  CHECK(cleared > (in_scene ? 20 : 100));
  CHECK(marked > 100);
  CHECK(costs_changed > scans / (in_scene ? 20 : 2));
  // Known directions spare beams that pass no obstacle cell (unknown ones, none: above); in a
  // game's scene, many.
  if (in_scene) CHECK(4 * tested < 3 * offered);
  MESSAGE("beams tested: " << tested << " of " << offered);
}

}  // namespace

TEST_CASE(
    "costmap: the laser update leaves the cells and costs of the textbook beam walk and "
    "inflation") {
  SUBCASE("the global costmap's resolution") { compare(0.05, 112, 96, 60, 360, 7); }
  SUBCASE("the local rolling window's") { compare(0.1, 30, 30, 200, 360, 11); }
  SUBCASE("few beams, coarse cells") { compare(0.25, 23, 17, 300, 17, 13); }
  SUBCASE("the local window rolling with its scans' origin") {
    compare(0.1, 30, 30, 200, 360, 17, true);
  }
  SUBCASE("moving discs: the global costmap's resolution") {
    compare(0.05, 112, 96, 80, 360, 37, false, Directions::kFull, Scene::kDiscs);
  }
  SUBCASE("moving discs: the local rolling window") {
    compare(0.1, 30, 30, 300, 360, 41, true, Directions::kFull, Scene::kDiscs);
  }
  SUBCASE("moving discs, a 240 degree scanner") {
    compare(0.05, 112, 96, 80, 682, 19, false, Directions::kPartial, Scene::kDiscs);
    compare(0.1, 30, 30, 300, 682, 23, true, Directions::kPartial, Scene::kDiscs);
  }
  SUBCASE("the beams' directions unknown: every beam tested") {
    compare(0.05, 112, 96, 40, 360, 29, false, Directions::kUnknown);
    compare(0.1, 30, 30, 100, 360, 31, true, Directions::kUnknown);
  }
}
