// SPDX-License-Identifier: MIT
// The move_base-2013 costmaps (docs/planner.md, "move_base-2013"): a static layer rasterised
// from the planner's exact map, laser obstacles marked at their hits and cleared along their
// beams (Bresenham), and the costmap_2d inflation written as a precomputed kernel.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "llsf/core/assert.h"
#include "llsf/core/geometry.h"
#include "llsf/planner/move_base.h"

namespace llsf::planner {

Costmap::Costmap(Vec2 origin, int nx, int ny, double resolution_m, const MoveBaseConfig& config)
    : origin_(origin),
      nx_(nx),
      ny_(ny),
      res_(resolution_m),
      raytrace_range_(config.raytrace_range_m),
      obstacle_range_(config.obstacle_range_m) {
  LLSF_DEMAND(nx > 0 && ny > 0 && resolution_m > 0.0);
  const std::size_t n = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  static_lethal_.assign(n, 0);
  static_cost_.assign(n, kFree);
  obstacle_.assign(n, 0);
  listed_.assign(n, 0);
  cost_.assign(n, kFree);
  // costmap_2d's cost of a cell at distance d (in cells, exact) from an obstacle cell: lethal on
  // it, inscribed within ceil(robot radius / resolution) cells, then
  // 252 * exp(-k (d res - robot radius)) out to ceil(inflation radius / resolution) cells.
  // Both radii are rounded up to whole cells as costmap_2d's cellDistance() does: with the 2013
  // figures (0.275 and 0.30 m) every cell within 0.30 m is inscribed, at 0.05 m and at 0.1 m.
  const int inscribed = static_cast<int>(std::ceil(config.robot_radius_m / res_ - 1e-9));
  const int r = static_cast<int>(std::ceil(config.inflation_radius_m / res_ - 1e-9));
  struct KernelCell {
    int di;
    int dj;
    std::uint8_t cost;
  };
  std::vector<KernelCell> kernel;
  for (int dj = -r; dj <= r; ++dj) {
    for (int di = -r; di <= r; ++di) {
      const double d = std::hypot(static_cast<double>(di), static_cast<double>(dj));
      if (d > r) continue;
      std::uint8_t c = 0;
      if (di == 0 && dj == 0) {
        c = kLethal;
      } else if (d <= inscribed) {
        c = kInscribed;
      } else {
        c = static_cast<std::uint8_t>(
            (kInscribed - 1) *
            std::exp(-config.cost_scaling_factor * (d * res_ - config.robot_radius_m)));
      }
      if (c > 0) kernel.push_back({di, dj, c});
    }
  }
  // The same kernel as row spans (zeros inside a span are harmless under max).
  for (int dj = -r; dj <= r; ++dj) {
    int lo = r + 1, hi = -r - 1;
    for (const KernelCell& k : kernel) {
      if (k.dj != dj) continue;
      lo = std::min(lo, k.di);
      hi = std::max(hi, k.di);
    }
    if (lo > hi) continue;
    KernelRow row{dj, lo, std::vector<std::uint8_t>(static_cast<std::size_t>(hi - lo + 1), 0)};
    for (const KernelCell& k : kernel) {
      if (k.dj == dj) row.costs[static_cast<std::size_t>(k.di - lo)] = k.cost;
    }
    if (row.costs.size() <= row.wide.size()) {
      std::copy(row.costs.begin(), row.costs.end(), row.wide.begin());
    }
    rows_.push_back(std::move(row));
    kernel_r_ = std::max(kernel_r_, std::max(std::abs(dj), std::max(-lo, hi)));
  }
}

void Costmap::stamp(std::vector<std::uint8_t>& grid, int i, int j, int ci0, int cj0, int ci1,
                    int cj1) const {
  for (const KernelRow& row : rows_) {
    const int b = j + row.dj;
    if (b < cj0 || b > cj1) continue;
    const int first = i + row.di0;
    const int a0 = std::max(ci0, first);
    const int a1 = std::min(ci1, first + static_cast<int>(row.costs.size()) - 1);
    std::uint8_t* out = grid.data() + idx(0, b);
    const int span = static_cast<int>(row.costs.size());
    if (span <= 16 && a0 == first && a1 == first + span - 1 && first + 16 <= nx_) {
      // The whole row of the kernel at once: 16 cells, maxed with its costs and zeros after
      // them (which leave the cells beyond the span as they are).
      using Bytes16 = std::uint8_t __attribute__((vector_size(16)));
      Bytes16 o, k;
      std::memcpy(&o, out + first, sizeof o);
      std::memcpy(&k, row.wide.data(), sizeof k);
      o = o > k ? o : k;
      std::memcpy(out + first, &o, sizeof o);
      continue;
    }
    const std::uint8_t* k = row.costs.data() - first;
    for (int a = a0; a <= a1; ++a) out[a] = std::max(out[a], k[a]);
  }
}

Vec2 Costmap::cell_center(int i, int j) const {
  return {origin_.x() + (i + 0.5) * res_, origin_.y() + (j + 0.5) * res_};
}

std::uint8_t Costmap::cost_at(const Vec2& p, bool outside_lethal) const {
  int i = 0, j = 0;
  if (!to_cell(p, i, j)) return outside_lethal ? kLethal : kFree;
  return cost(i, j);
}

std::uint8_t Costmap::static_cost_at(const Vec2& p) const {
  int i = 0, j = 0;
  if (!to_cell(p, i, j)) return kLethal;
  return static_cost_[idx(i, j)];
}

void Costmap::set_static(const Planner& planner) {
  // A cell is a static obstacle when an obstacle or a wall reaches into it (its centre is
  // within half a cell of one), as the pixels of the team's map image marked them.
  for (int j = 0; j < ny_; ++j) {
    for (int i = 0; i < nx_; ++i) {
      const double d = planner.clearance(cell_center(i, j)).distance_m;
      static_lethal_[idx(i, j)] = d <= 0.5 * res_ ? 1 : 0;
    }
  }
  std::fill(static_cost_.begin(), static_cost_.end(), kFree);
  for (int j = 0; j < ny_; ++j) {
    for (int i = 0; i < nx_; ++i) {
      if (static_lethal_[idx(i, j)] != 0) stamp(static_cost_, i, j);
    }
  }
  for (std::size_t n = 0; n < obstacle_.size(); ++n) {
    if (static_lethal_[n] != 0) obstacle_[n] = 0;
  }
  mark_all_dirty();
}

void Costmap::recenter(const Vec2& center) {
  // As costmap_2d's rolling window: the origin moves by whole cells, what stays is kept.
  const Vec2 wanted(center.x() - 0.5 * nx_ * res_, center.y() - 0.5 * ny_ * res_);
  const int si = static_cast<int>(std::floor((wanted.x() - origin_.x()) / res_));
  const int sj = static_cast<int>(std::floor((wanted.y() - origin_.y()) / res_));
  if (si == 0 && sj == 0) return;
  std::vector<std::uint8_t>& moved = scratch_;
  moved.assign(obstacle_.size(), 0);
  for (int j = 0; j < ny_; ++j) {
    const int oj = j + sj;
    if (oj < 0 || oj >= ny_) continue;
    for (int i = 0; i < nx_; ++i) {
      const int oi = i + si;
      if (oi < 0 || oi >= nx_) continue;
      moved[idx(i, j)] = obstacle_[idx(oi, oj)];
    }
  }
  obstacle_.swap(moved);
  relist();
  origin_ = Vec2(origin_.x() + si * res_, origin_.y() + sj * res_);
  mark_all_dirty();
}

void Costmap::update(const Vec2& origin, std::span<const Vec2> hits, const Beams& beams,
                     const Vec2& robot, double radius_m) {
  mark_and_clear(origin, hits, beams);
  erase_within(robot, radius_m);
}

bool Costmap::clear_footprint(const Vec2& center, double radius_m) {
  return erase_within(center, radius_m);
}

bool Costmap::erase_within(const Vec2& center, double radius_m) {
  // The cells whose centres lie inside the circle (costmap_2d fills a 72-gon of it).
  bool any = false;
  int i0 = 0, j0 = 0, i1 = 0, j1 = 0;
  const Vec2 lo = center - Vec2(radius_m, radius_m);
  const Vec2 hi = center + Vec2(radius_m, radius_m);
  i0 = std::max(0, static_cast<int>(std::floor((lo.x() - origin_.x()) / res_)));
  j0 = std::max(0, static_cast<int>(std::floor((lo.y() - origin_.y()) / res_)));
  i1 = std::min(nx_ - 1, static_cast<int>(std::floor((hi.x() - origin_.x()) / res_)));
  j1 = std::min(ny_ - 1, static_cast<int>(std::floor((hi.y() - origin_.y()) / res_)));
  const double r2 = radius_m * radius_m;
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      if ((cell_center(i, j) - center).squaredNorm() > r2) continue;
      std::uint8_t& o = obstacle_[idx(i, j)];
      if (o != 0) {
        o = 0;
        any = true;
        mark_dirty(i, j);
      }
    }
  }
  return any;
}

namespace {

// The octants around a cell: bit 0 x negative, bit 1 y negative, bit 2 |y| > |x|. A direction's
// octant, and whether an offset lies in an octant with its boundaries.
int octant_of(int a, int b) {
  return (a < 0 ? 1 : 0) | (b < 0 ? 2 : 0) | (std::abs(b) > std::abs(a) ? 4 : 0);
}
bool in_closed_octant(int o, int a, int b) {
  return ((o & 1) != 0 ? a <= 0 : a >= 0) && ((o & 2) != 0 ? b <= 0 : b >= 0) &&
         ((o & 4) != 0 ? std::abs(b) >= std::abs(a) : std::abs(a) >= std::abs(b));
}

}  // namespace

void Costmap::set_obstacle(std::size_t k) {
  if (obstacle_[k] != 0) return;
  obstacle_[k] = 1;
  if (listed_[k] == 0) {
    listed_[k] = 1;
    obstacle_list_.push_back(static_cast<int>(k));
  }
}

void Costmap::relist() const {
  obstacle_list_.clear();
  std::fill(listed_.begin(), listed_.end(), 0);
  for (std::size_t k = 0; k < obstacle_.size(); ++k) {
    if (obstacle_[k] != 0) {
      listed_[k] = 1;
      obstacle_list_.push_back(static_cast<int>(k));
    }
  }
}

void Costmap::beams_near(const Vec2& origin, std::size_t hits, const Beams& beams, int i0, int j0) {
  beam_todo_.clear();
  auto all = [&] {
    beam_todo_.resize(hits);
    for (std::size_t k = 0; k < hits; ++k) beam_todo_[k] = static_cast<int>(k);
  };
  const int count = beams.count;
  if (beams.of_hit.empty() || count <= 0 || !(beams.increment_rad > 0.0)) return all();
  LLSF_ASSERT(beams.of_hit.size() == hits);
  // A beam clears the cells of the Bresenham line from the origin's cell to its end cell: each
  // within half a cell (across the line) of the segment between the two cells' centres, which
  // lies within sqrt(2) / 2 cells of the beam (the origin and the end point are inside those
  // cells). So a cell the beam clears has its centre within 0.5 + 0.7072 cells of the beam: at
  // a distance D (cells) from the origin, in a direction less than asin(1.2072 / D) from the
  // beam's. Looked at: the beams within 1.155 x >= asin(x) (x = 1.25 / D <= 0.5) and 0.01 rad
  // (more than core::rough_atan2's error) of some obstacle cell's direction; every beam when a
  // cell is nearer than 2.5 cells.
  constexpr double kTwoPi = 2.0 * core::kPi;
  constexpr double kReach = 1.25;
  beam_marks_.assign(static_cast<std::size_t>(count) + 1, 0);
  const double inv_inc = 1.0 / beams.increment_rad;
  const double per_turn = kTwoPi * inv_inc;  // beams
  for (const OffsetCell& cell : reach_cells_) {
    const double qx = origin_.x() + (i0 + cell.a + 0.5) * res_ - origin.x();
    const double qy = origin_.y() + (j0 + cell.b + 0.5) * res_ - origin.y();
    const double x = kReach * res_ / std::sqrt(qx * qx + qy * qy);
    if (!(x <= 0.5)) return all();
    static_assert(core::kRoughAtan2Error < 0.01);
    const double w = 1.155 * x + 0.01;
    const double phi = core::rough_atan2(qy, qx);
    double lo = (phi - w - beams.first_rad) * inv_inc, hi = (phi + w - beams.first_rad) * inv_inc;
    const double turns = std::floor(lo / per_turn);  // lo into [0, per_turn)
    lo -= turns * per_turn;
    hi -= turns * per_turn;
    for (int s = -1; s <= 1; ++s) {
      const double a = std::max(0.0, lo + s * per_turn);
      const double b = std::min(count - 1.0, hi + s * per_turn);
      if (!(a <= b)) continue;
      const auto first = static_cast<int>(std::ceil(a)), last = static_cast<int>(std::floor(b));
      if (first > last) continue;
      ++beam_marks_[static_cast<std::size_t>(first)];
      --beam_marks_[static_cast<std::size_t>(last) + 1];
    }
  }
  // The marks summed in place: beam k is wanted when beam_marks_[k] is 1.
  int open = 0;
  for (int& mark : beam_marks_) {
    open += mark;
    mark = open > 0 ? 1 : 0;
  }
  beam_todo_.resize(hits);
  std::size_t todo = 0;
  for (std::size_t k = 0; k < hits; ++k) {
    const int beam = beams.of_hit[k];
    LLSF_ASSERT(beam >= 0 && beam < count);
    beam_todo_[todo] = static_cast<int>(k);
    todo += static_cast<std::size_t>(beam_marks_[static_cast<std::size_t>(beam)]);
  }
  beam_todo_.resize(todo);
}

template <class F>
void Costmap::for_each_obstacle(int i0, int j0, int i1, int j1, F&& f) const {
  std::size_t kept = 0;
  for (std::size_t n = 0; n < obstacle_list_.size(); ++n) {
    const int k = obstacle_list_[n];
    if (obstacle_[static_cast<std::size_t>(k)] == 0) {  // cleared since it was listed
      listed_[static_cast<std::size_t>(k)] = 0;
      continue;
    }
    obstacle_list_[kept++] = k;
    const int j = k / nx_, i = k - j * nx_;
    if (i >= i0 && i <= i1 && j >= j0 && j <= j1) f(i, j);
  }
  obstacle_list_.resize(kept);
}

void Costmap::mark_and_clear(const Vec2& origin, std::span<const Vec2> hits, const Beams& beams) {
  int i0 = 0, j0 = 0;
  const bool origin_in = to_cell(origin, i0, j0);
  const int max_cells = static_cast<int>(raytrace_range_ / res_);
  beams_tested_ = 0;
  // 1. Clear free space along every beam (not its end cell), up to the raytrace range: the
  // cells of a Bresenham line from the origin's cell towards the end's. Only laser obstacle
  // cells can change, so each beam is tested against them instead of walked: the line's k-th
  // cell lies k cells along its major axis, and its minor offset has a closed form (below), so
  // a cell is on the line iff it sits at that offset, fewer than the line's steps away. Each
  // cell can only be on lines in the closed octants that hold it; the cells are kept by octant.
  if (origin_in) {
    for (auto& list : octant_cells_) list.clear();
    reach_cells_.clear();
    const int bi0 = std::max(0, i0 - max_cells), bi1 = std::min(nx_ - 1, i0 + max_cells);
    const int bj0 = std::max(0, j0 - max_cells), bj1 = std::min(ny_ - 1, j0 + max_cells);
    bool any = false;
    for_each_obstacle(bi0, bj0, bi1, bj1, [&](int i, int j) {
      const int a = i - i0, b = j - j0;
      for (int o = 0; o < 8; ++o) {
        if (in_closed_octant(o, a, b)) octant_cells_[o].push_back({a, b});
      }
      reach_cells_.push_back({a, b});
      any = true;
    });
    // Each cell by slope bins: a cell k cells along the major axis and m along the minor one is
    // on the lines of slopes in ((2m - 1) / 2k, (2m + 1) / 2k] (the closed form below), so a
    // line needs to test only the cells of its slope's bin.
    constexpr int kB = kSlopeBins;
    auto slope_bins = [](const OffsetCell& cell, int o, int& lo, int& hi) {
      const int a = (o & 1) != 0 ? -cell.a : cell.a, b = (o & 2) != 0 ? -cell.b : cell.b;
      const int k = (o & 4) != 0 ? b : a, m = (o & 4) != 0 ? a : b;
      if (k == 0) {  // the origin's own cell: on every line
        lo = 0;
        hi = kB - 1;
        return;
      }
      lo = m == 0 ? 0 : ((2 * m - 1) * kB) / (2 * k);
      hi = std::min(kB - 1, ((2 * m + 1) * kB) / (2 * k));
    };
    slope_start_.fill(0);
    for (int o = 0; o < 8; ++o) {
      for (const OffsetCell& cell : octant_cells_[o]) {
        int lo = 0, hi = 0;
        slope_bins(cell, o, lo, hi);
        for (int b = lo; b <= hi; ++b) ++slope_start_[o * kB + b + 1];
      }
    }
    for (std::size_t n = 1; n < slope_start_.size(); ++n) slope_start_[n] += slope_start_[n - 1];
    slope_cells_.resize(static_cast<std::size_t>(slope_start_.back()));
    {
      std::array<int, 8 * kB + 1> fill = slope_start_;
      for (int o = 0; o < 8; ++o) {
        for (const OffsetCell& cell : octant_cells_[o]) {
          int lo = 0, hi = 0;
          slope_bins(cell, o, lo, hi);
          const int a = (o & 1) != 0 ? -cell.a : cell.a, b = (o & 2) != 0 ? -cell.b : cell.b;
          const BinCell bc{static_cast<std::int16_t>(cell.a), static_cast<std::int16_t>(cell.b),
                           static_cast<std::int16_t>((o & 4) != 0 ? b : a),
                           static_cast<std::int16_t>((o & 4) != 0 ? a : b),
                           static_cast<std::ptrdiff_t>(cell.b) * nx_ + cell.a};
          for (int bin = lo; bin <= hi; ++bin) {
            slope_cells_[static_cast<std::size_t>(fill[o * kB + bin]++)] = bc;
          }
        }
      }
    }
    // (The grid's figures in locals: the obstacle cells' byte stores below could alias them.)
    const double x_lo = origin_.x(), y_lo = origin_.y(), res = res_;
    const double x_hi = origin_.x() + nx_ * res_ - 1e-9, y_hi = origin_.y() + ny_ * res_ - 1e-9;
    const int nx = nx_, ny = ny_;
    std::uint8_t* const base = obstacle_.data() + idx(i0, j0);
    constexpr int kNone = std::numeric_limits<int>::max();
    int di0 = kNone, dj0 = kNone, di1 = -1, dj1 = -1;  // the cells cleared
    // Two passes: first each beam's line and the cells of its bin, without a branch that
    // depends on the beam (most bins are empty, and which ones is as good as random: a
    // mispredicted branch there cost more than the rest of the beam); then the beams whose bin
    // holds cells.
    if (any) beams_near(origin, hits.size(), beams, i0, j0);
    beams_tested_ = any ? beam_todo_.size() : 0;
    beam_lines_.resize(any ? beam_todo_.size() : 0);
    std::size_t lines = 0;
    for (const int beam : any ? std::span<const int>(beam_todo_) : std::span<const int>{}) {
      const Vec2& h = hits[static_cast<std::size_t>(beam)];
      // The end point, clipped to the grid along the beam (these branches follow the beams'
      // directions, which change slowly).
      Vec2 e = h;
      const Vec2 d = e - origin;
      double t = 1.0;
      if (e.x() < x_lo) t = std::min(t, (x_lo - origin.x()) / d.x());
      if (e.x() > x_hi) t = std::min(t, (x_hi - origin.x()) / d.x());
      if (e.y() < y_lo) t = std::min(t, (y_lo - origin.y()) / d.y());
      if (e.y() > y_hi) t = std::min(t, (y_hi - origin.y()) / d.y());
      e = origin + d * t;
      // to_cell(e, i1, j1); a beam whose end is outside (by rounding) clears nothing.
      const double fx = (e.x() - x_lo) / res;
      const double fy = (e.y() - y_lo) / res;
      bool valid = (fx >= 0.0) & (fy >= 0.0);
      const int i1 = static_cast<int>(valid ? std::min(fx, double(nx)) : 0.0);
      const int j1 = static_cast<int>(valid ? std::min(fy, double(ny)) : 0.0);
      valid = valid & (i1 < nx) & (j1 < ny);
      const int da = i1 - i0, db = j1 - j0;
      const int dx = std::abs(da), dy = std::abs(db);
      const int steps = std::min(std::max(dx, dy), max_cells);
      valid = valid & (steps != 0);
      const bool x_major = dx >= dy;
      const int major = std::max(1, x_major ? dx : dy), minor = x_major ? dy : dx;
      const int bin = octant_of(da, db) * kB + std::min(kB - 1, (minor * kB) / major);
      const int first = slope_start_[static_cast<std::size_t>(bin)];
      const int last = valid ? slope_start_[static_cast<std::size_t>(bin) + 1] : first;
      beam_lines_[lines] = {first, last, steps, major, minor};
      lines += last > first ? 1 : 0;
    }
    for (std::size_t n = 0; n < lines; ++n) {
      const BeamLine& line = beam_lines_[n];
      const int steps = line.steps, major = line.major, minor = line.minor;
      // (No branch per cell: whether a cell is cleared is as good as random.)
      const int den = 2 * major;
      for (int c = line.first; c < line.last; ++c) {
        const BinCell& cell = slope_cells_[static_cast<std::size_t>(c)];
        std::uint8_t* o = base + cell.at;
        // The textbook Bresenham's minor offset at major step k is ceil(num / den) with
        // num = 2 k minor - major and den = 2 major (checked against the walk for every line
        // up to 90 cells): m is it iff (m - 1) den < num <= m den.
        const int num = 2 * cell.k * minor - major;
        const bool hit =
            (*o != 0) & (cell.k < steps) & (num <= cell.m * den) & (num > (cell.m - 1) * den);
        *o = hit ? 0 : *o;
        const int ci = i0 + cell.a, cj = j0 + cell.b;
        di0 = std::min(di0, hit ? ci : kNone);
        dj0 = std::min(dj0, hit ? cj : kNone);
        di1 = std::max(di1, hit ? ci : -1);
        dj1 = std::max(dj1, hit ? cj : -1);
      }
    }
    dirty_i0_ = std::min(dirty_i0_, di0);
    dirty_j0_ = std::min(dirty_j0_, dj0);
    dirty_i1_ = std::max(dirty_i1_, di1);
    dirty_j1_ = std::max(dirty_j1_, dj1);
  }
  // 2. Mark the hits within the obstacle range.
  const double r2 = obstacle_range_ * obstacle_range_;
  for (const Vec2& h : hits) {
    if ((h - origin).squaredNorm() >= r2) continue;
    int i = 0, j = 0;
    if (!to_cell(h, i, j)) continue;
    if (static_lethal_[idx(i, j)] != 0) continue;  // already an obstacle for good
    if (obstacle_[idx(i, j)] == 0) {
      set_obstacle(idx(i, j));
      mark_dirty(i, j);
    }
  }
}

void Costmap::reset_outside(const Vec2& center, double size_m) {
  const double h = 0.5 * size_m;
  for (int j = 0; j < ny_; ++j) {
    for (int i = 0; i < nx_; ++i) {
      const Vec2 c = cell_center(i, j);
      if (std::abs(c.x() - center.x()) > h || std::abs(c.y() - center.y()) > h) {
        std::uint8_t& o = obstacle_[idx(i, j)];
        if (o != 0) {
          o = 0;
          mark_dirty(i, j);
        }
      }
    }
  }
}

void Costmap::inflate() const {
  if (dirty_i0_ > dirty_i1_) return;  // no laser obstacle changed: nor did a cost
  // The cells a changed obstacle cell reaches, and the obstacle cells that reach them.
  const int r = kernel_r_;
  const int ri0 = std::max(0, dirty_i0_ - r), ri1 = std::min(nx_ - 1, dirty_i1_ + r);
  const int rj0 = std::max(0, dirty_j0_ - r), rj1 = std::min(ny_ - 1, dirty_j1_ + r);
  const int oi0 = std::max(0, ri0 - r), oi1 = std::min(nx_ - 1, ri1 + r);
  const int oj0 = std::max(0, rj0 - r), oj1 = std::min(ny_ - 1, rj1 + r);
  const std::size_t n = static_cast<std::size_t>(ri1 - ri0 + 1);
  for (int j = rj0; j <= rj1; ++j) {
    std::memcpy(cost_.data() + idx(ri0, j), static_cost_.data() + idx(ri0, j), n);
  }
  for_each_obstacle(oi0, oj0, oi1, oj1,
                    [&](int i, int j) { stamp(cost_, i, j, ri0, rj0, ri1, rj1); });
  dirty_i0_ = dirty_j0_ = std::numeric_limits<int>::max();
  dirty_i1_ = dirty_j1_ = -1;
}

}  // namespace llsf::planner
