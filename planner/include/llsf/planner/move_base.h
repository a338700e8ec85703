// SPDX-License-Identifier: MIT
// The `move_base-2013` navigation level: the 2013 Carologistics Robotino's ROS move_base as its
// team configured it (repository carologistics/fawkes-robotino, commit 6cffc15f2,
// cfg/move_base_robotino/), written here from the behaviour ROS navigation (groovy) documents:
// a global costmap on the static map plus laser obstacles, a local rolling costmap of laser
// obstacles only, a navfn-style Dijkstra planner on the inflated global costmap, a
// TrajectoryPlannerROS-style rollout controller (dwa mode, holonomic), and move_base's state
// machine (planning, controlling, clearing) with its default recovery sequence. Other robots
// exist for it only as laser hits. docs/planner.md ("move_base-2013") gives every figure with
// its source.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "llsf/core/sim_time.h"
#include "llsf/planner/navigator.h"
#include "llsf/planner/planner.h"

namespace llsf::planner {

/// Every figure of the level. Defaults are the 2013 files' values where they set one, else the
/// ROS navigation (groovy) default; docs/planner.md cites each.
struct MoveBaseConfig {
  // costmap_common_params.yaml
  double robot_radius_m = 0.275;      ///< inscribed radius: closer to an obstacle is a collision
  double inflation_radius_m = 0.30;   ///< costs fall off to this distance
  double cost_scaling_factor = 10.0;  ///< costmap_2d default (exp(-k (d - inscribed)))
  double obstacle_range_m = 3.0;      ///< laser hits nearer than this are marked
  double raytrace_range_m = 3.0;      ///< free space is cleared along beams this far
  // local_costmap_params.yaml (rolling window, laser only)
  double local_size_m = 3.0;
  double local_resolution_m = 0.1;
  double local_update_hz = 5.0;
  // global_costmap_params.yaml (static map + laser); map/map.yaml resolution
  double global_resolution_m = 0.05;
  double global_update_hz = 2.0;
  // base_local_planner_params.yaml (TrajectoryPlannerROS)
  double max_vel_x = 0.5;
  double min_vel_x = 0.1;
  double max_rotational_vel = 0.78;
  double min_in_place_rotational_vel = 0.3;
  double acc_lim_x = 2.5;
  double acc_lim_y = 2.5;
  double acc_lim_th = 3.2;
  double xy_goal_tolerance_m = 0.15;
  double yaw_goal_tolerance_rad = 0.1;
  double path_distance_bias = 1.0;
  double sim_time_s = 2.0;
  // TrajectoryPlannerROS defaults (the 2013 file is silent)
  double goal_distance_bias = 0.8;
  double occdist_scale = 0.01;
  double sim_granularity_m = 0.025;
  int vx_samples = 3;
  int vtheta_samples = 20;
  double heading_lookahead_m = 0.325;
  double oscillation_reset_dist_m = 0.05;
  double escape_reset_dist_m = 0.10;
  double escape_reset_theta_rad = 0.7853981633974483;  // pi/4
  double escape_vel_mps = -0.1;
  double stopped_vel = 0.01;  ///< trans/rot velocity below which the robot counts as stopped
  // move_base.launch
  double controller_frequency_hz = 5.0;
  double conservative_reset_dist_m = 5.6;
  bool recovery_behavior_enabled = true;
  bool shutdown_costmaps = true;
  // move_base defaults (the 2013 files leave them unset)
  double planner_patience_s = 5.0;
  double controller_patience_s = 15.0;
  double circumscribed_radius_m = 0.46;  ///< aggressive reset keeps 4x this square
  bool clearing_rotation_allowed = true;
  // rotate_recovery defaults
  double rotate_sim_granularity_rad = 0.017;
  // A robot that starts inside the inscribed radius of a static obstacle (at a machine, in the
  // insertion area) first moves straight out to the nearest free point within this distance,
  // as the 2013 skills did before every ppgoto (leave_area: motor_move x = -0.2; leave_IS).
  double depart_max_m = 0.6;
  // The straight moves (departure and final approach) are the team's motor_move
  // (fawkes-robotino 6cffc15f2, src/lua/skills/robotino/motor_move.lua): per axis of the robot
  // frame, a speed proportional to the distance left (V_MAX / D_DECEL / 5: 0.4 / 0.07 / 5 m/s
  // per m, 2.2 / 0.2 / 5 rad/s per rad), at least V_MIN (0.035 m/s, 0.15 rad/s), at most
  // the move's cap; an axis within TOLERANCE (0.04 m, 0.05 rad) stops; no timeout.
  double motor_gain_xy = 0.4 / 0.07 / 5.0;
  double motor_gain_th = 2.2 / 0.2 / 5.0;
  double motor_min_speed_mps = 0.035;
  double motor_min_omega_rps = 0.15;
  double motor_omega_rps = 2.2;   ///< V_MAX.ori: the cap of every straight move's turn
  double depart_speed_mps = 0.4;  ///< V_MAX.x: leave_area and leave_IS use motor_move's default
  double depart_tolerance_m = 0.04;
  double depart_angle_tolerance_rad = 0.05;
  // The final approach to a goal move_base cannot take (a pose at a machine, inside the
  // inscribed radius of its footprint): move_base drives to the nearest pose back along the
  // goal heading that its costmap allows, then a straight relative move, as the 2013 skills did
  // (ppgoto to a navgraph node, then move_under_rfid: turn, APPROACH_AMPEL at vel_trans 0.1).
  double approach_speed_mps = 0.1;
  double approach_tolerance_m = 0.02;
  double approach_angle_tolerance_rad = 0.03;

  // ppgoto: the 2013 skills did not send move_base across the field; Fawkes' navgraph plugin
  // (fawkesrobotics/fawkes bb80e90bc, 2013-07-13, src/plugins/navgraph/navgraph_thread.cpp)
  // led the robot along the team's navigation graph (cfg/navgraph-llsf.yaml at 6cffc15f2),
  // sending move_base one node after the other, resending the current one every
  // resend_interval and never failing on move_base's abort (docs/planner.md). A goal nearer
  // than `navgraph_direct_m` goes to move_base directly (the skills' relgoto).
  bool navgraph = true;
  double navgraph_direct_m = 1.0;
  // cfg/conf.d/navgraph.yaml (6cffc15f2)
  double navgraph_travel_tolerance_m = 0.4;   ///< a node passed (unless the node says otherwise)
  double navgraph_target_tolerance_m = 0.25;  ///< the final target reached ...
  double navgraph_orientation_tolerance_rad = 0.2;  ///< ... and facing its heading
  double navgraph_resend_interval_s = 6.0;          ///< the current goal sent again after this
  double navgraph_target_time_s = 10.0;             ///< move_base kept going after the target

  /// The clearance (robot centre to the nearest static obstacle or wall) of the pose move_base
  /// drives to instead of a goal too close to an obstacle, and of the point a departure goes
  /// to: where both costmaps see the robot free however their cells fall -- the robot radius
  /// rounded up to whole cells of the coarser map (costmap_2d's cellDistance), plus two such
  /// cells: the robot's and the obstacle's cell centres may each be half a cell off, and the
  /// laser's noise, the localization's error and the stop tolerance need the second
  /// (0.30 + 0.2 = 0.50 m with the 2013 figures).
  double standoff_m() const;

  /// Throws core::ConfigError naming the field ("move_base.sim_time_s: must be > 0").
  void validate() const;
};

/// A 2D cost grid as costmap_2d keeps it: 0 free .. 252 inflated, 253 inscribed (a collision for
/// a robot centred there), 254 lethal (an obstacle cell).
class Costmap {
 public:
  static constexpr std::uint8_t kFree = 0;
  static constexpr std::uint8_t kInscribed = 253;
  static constexpr std::uint8_t kLethal = 254;

  /// Where a scan's beams point: hit k came from beam of_hit[k], in the direction
  /// first_rad + of_hit[k] * increment_rad (field frame), of `count` beams in all. Empty
  /// of_hit: not known.
  struct Beams {
    double first_rad = 0.0;
    double increment_rad = 0.0;
    int count = 0;
    std::span<const int> of_hit;
  };

  Costmap() = default;
  /// A grid of `nx` x `ny` cells of `resolution_m`, its lower-left corner at `origin`.
  Costmap(Vec2 origin, int nx, int ny, double resolution_m, const MoveBaseConfig& config);

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  double resolution() const { return res_; }
  Vec2 origin() const { return origin_; }
  /// The cell holding `p`; false outside the grid.
  bool to_cell(const Vec2& p, int& i, int& j) const {
    const double fx = (p.x() - origin_.x()) / res_;
    const double fy = (p.y() - origin_.y()) / res_;
    if (!(fx >= 0.0 && fy >= 0.0)) return false;
    i = static_cast<int>(fx);
    j = static_cast<int>(fy);
    return i < nx_ && j < ny_;
  }
  Vec2 cell_center(int i, int j) const;
  std::uint8_t cost(int i, int j) const {
    settle();
    return cost_[idx(i, j)];
  }
  /// The costs, row by row (cell (i, j) at j * nx() + i).
  const std::uint8_t* cost_data() const {
    settle();
    return cost_.data();
  }
  /// Cost at a point; outside the grid: kLethal if `outside_lethal`, else kFree.
  std::uint8_t cost_at(const Vec2& p, bool outside_lethal = true) const;
  bool obstacle(int i, int j) const { return obstacle_[idx(i, j)] != 0; }
  /// The static layer's cost at a point (outside the grid: kLethal).
  std::uint8_t static_cost_at(const Vec2& p) const;

  /// The static layer: cells an obstacle of `planner`'s map (or a wall) covers are lethal for
  /// good; the rest is inflated from them.
  void set_static(const Planner& planner);
  /// Moves a rolling window so that `center` is in its middle cell; cells that enter are free.
  void recenter(const Vec2& center);
  /// One sensor update: clear the cells along every beam from `origin` to its hit (within
  /// raytrace range), mark the hits within obstacle range, then, as costmap_2d's
  /// clearRobotFootprint(), forget the laser obstacles within `radius_m` of `robot`; the costs
  /// are inflated again when next read. With `beams` known, only the beams that pass near a
  /// laser obstacle cell are looked at (the same cells result).
  void update(const Vec2& origin, std::span<const Vec2> hits, const Beams& beams, const Vec2& robot,
              double radius_m);
  /// The beams the last update() tested against its laser obstacle cells (all its hits when
  /// their directions are unknown; none when no obstacle cell was in reach).
  std::size_t beams_tested() const { return beams_tested_; }
  /// costmap_2d's clearRobotFootprint(), after every update and before every controller cycle:
  /// laser obstacle cells within `radius_m` of `center` (the robot's inscribed circle) are
  /// forgotten (the costs inflated again when next read). Returns whether a cell was cleared.
  bool clear_footprint(const Vec2& center, double radius_m);
  /// ClearCostmapRecovery: laser obstacles outside the square of side `size_m` around `center`
  /// are forgotten (the static map remains).
  void reset_outside(const Vec2& center, double size_m);

 private:
  std::size_t idx(int i, int j) const {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(nx_) +
           static_cast<std::size_t>(i);
  }
  // Inflates the cells the laser obstacles changed since the last call could reach (all of them
  // after set_static or recenter): only those cells' costs can differ.
  void inflate() const;
  // The costs are inflated when they are read after a change, not at every change (the global
  // costmap changes at 2 Hz and is read by each global plan): the same costs, as inflation
  // depends only on the obstacles, not on when it ran.
  void settle() const {
    if (dirty_i0_ <= dirty_i1_) inflate();
  }
  void mark_dirty(int i, int j) {
    dirty_i0_ = std::min(dirty_i0_, i);
    dirty_j0_ = std::min(dirty_j0_, j);
    dirty_i1_ = std::max(dirty_i1_, i);
    dirty_j1_ = std::max(dirty_j1_, j);
  }
  void mark_all_dirty() { dirty_i0_ = 0, dirty_j0_ = 0, dirty_i1_ = nx_ - 1, dirty_j1_ = ny_ - 1; }
  void mark_and_clear(const Vec2& origin, std::span<const Vec2> hits, const Beams& beams);
  // The beams (indices into the hits) that may clear one of the obstacle cells reach_cells_
  // (offsets from the origin's cell (i0, j0)): into beam_todo_.
  void beams_near(const Vec2& origin, std::size_t hits, const Beams& beams, int i0, int j0);
  bool erase_within(const Vec2& center, double radius_m);

  Vec2 origin_{0.0, 0.0};
  int nx_ = 0;
  int ny_ = 0;
  double res_ = 0.1;
  std::vector<std::uint8_t> static_lethal_;  // 1 = static obstacle
  std::vector<std::uint8_t> static_cost_;    // inflated static layer
  std::vector<std::uint8_t> obstacle_;       // 1 = laser obstacle
  mutable std::vector<std::uint8_t> cost_;   // combined, inflated (settle())
  std::vector<std::uint8_t> scratch_;        // recenter()'s moved obstacles (kept to reuse)
  // The laser obstacle cells (indices), so that a search for them need not scan the grid (a
  // map holds a few dozen); a cell cleared since it was listed is dropped by the next search.
  // listed_[k]: whether k is in the list.
  mutable std::vector<int> obstacle_list_;
  mutable std::vector<std::uint8_t> listed_;
  // Sets cell k's laser obstacle (and lists it).
  void set_obstacle(std::size_t k);
  // The list made again from the grid (after the grid moved).
  void relist() const;
  // Calls f(i, j) for every laser obstacle cell in columns [i0, i1] and rows [j0, j1], in no
  // particular order (what the callers do with them does not depend on it).
  template <class F>
  void for_each_obstacle(int i0, int j0, int i1, int j1, F&& f) const;
  // mark_and_clear(): the laser obstacle cells within reach, as offsets from the scan's origin
  // cell, by the closed octants around it that hold them.
  struct OffsetCell {
    int a;
    int b;
  };
  std::array<std::vector<OffsetCell>, 8> octant_cells_;
  // ... and by the slopes of the lines through them: bin b of octant o holds the cells whose
  // lines' slopes (minor / major) reach [b / kSlopeBins, (b + 1) / kSlopeBins] (a flat list,
  // bin o * kSlopeBins + b starting at slope_start_[o * kSlopeBins + b]).
  static constexpr int kSlopeBins = 64;
  // (Each as its octant sees it: k cells along the major axis, m along the minor one, and its
  // index relative to the origin cell's.)
  struct BinCell {
    std::int16_t a, b;  // the offset (for the changed region)
    std::int16_t k, m;
    std::ptrdiff_t at;  // b * nx + a
  };
  std::vector<BinCell> slope_cells_;
  std::array<int, 8 * kSlopeBins + 1> slope_start_{};
  // The beams whose bin holds cells: the bin's range in slope_cells_ and the beam's line.
  struct BeamLine {
    int first, last;   // slope_cells_[first, last)
    int steps;         // cells of the line that are cleared (its end cell is not)
    int major, minor;  // the line's extent along its major and minor axis
  };
  std::vector<BeamLine> beam_lines_;
  std::vector<OffsetCell> reach_cells_;  // the obstacle cells within reach of a scan
  std::vector<int> beam_marks_;          // beams_near(): +1 where a window starts, -1 after it
  std::vector<int> beam_todo_;           // the beams to look at
  std::size_t beams_tested_ = 0;
  struct KernelRow {  // the inflation kernel by rows: costs of cells di0, di0 + 1, ... of row dj
    int dj;
    int di0;
    std::vector<std::uint8_t> costs;
    std::array<std::uint8_t, 16> wide{};  // `costs` and zeros (when it has at most 16 cells)
  };
  std::vector<KernelRow> rows_;
  int kernel_r_ = 0;  // the largest |dj| (and |di|) of the kernel
  // The cells whose laser obstacle changed since the last inflate() (none: i0 > i1).
  mutable int dirty_i0_ = std::numeric_limits<int>::max();
  mutable int dirty_j0_ = std::numeric_limits<int>::max();
  mutable int dirty_i1_ = -1, dirty_j1_ = -1;
  // Raises `grid`'s cells within columns [ci0, ci1] and rows [cj0, cj1] to the kernel around
  // (i, j).
  void stamp(std::vector<std::uint8_t>& grid, int i, int j, int ci0, int cj0, int ci1,
             int cj1) const;
  void stamp(std::vector<std::uint8_t>& grid, int i, int j) const {
    stamp(grid, i, j, 0, 0, nx_ - 1, ny_ - 1);
  }
  double raytrace_range_ = 3.0;
  double obstacle_range_ = 3.0;
};

/// move_base's state (MoveBaseNavigator::state()).
enum class MoveBaseState {
  kIdle,
  kPlanning,
  kControlling,
  kClearing,  ///< a recovery behaviour runs
  kApproach,  ///< the straight final move after move_base reached the approach pose
  kDepart,    ///< the straight move out of an obstacle's inscribed radius before planning
  kAborted,   ///< move_base gave up; Fawkes' navgraph sends the goal again (ppgoto)
};
const char* to_string(MoveBaseState state);

/// Counters of one navigation (reset by go_to).
struct MoveBaseStats {
  int plans = 0;              ///< global plans made
  int plan_failures = 0;      ///< global planning attempts that found no path
  int control_failures = 0;   ///< controller cycles without a valid command
  int escapes = 0;            ///< controller cycles that backed off (escape velocity)
  int waypoints = 0;          ///< navigation-graph nodes passed on the way (ppgoto)
  int resends = 0;            ///< goals the navgraph sent again (ppgoto)
  int aborts = 0;             ///< move_base aborts the navgraph outlived (ppgoto)
  int recoveries = 0;         ///< recovery behaviours run
  int rotate_recoveries = 0;  ///< of them, in-place rotations
  double recovery_s = 0.0;    ///< time spent in recovery behaviours
  double stopped_s = 0.0;     ///< time commanded to stand (no valid control, planning)
};

/// One navigation stack of one robot, stepped in simulated time. Deterministic: no randomness,
/// no wall clock. Not thread-safe.
class MoveBaseNavigator {
 public:
  MoveBaseNavigator(const Planner& planner, MoveBaseConfig config);

  void go_to(const Pose2D& goal, bool forward = false);
  void go_to_place(std::string_view name, bool forward = false);
  void abort();

  /// A laser scan in field coordinates: the sensor's position, the points it hit and where
  /// their beams point (may be unknown: Costmap::Beams).
  struct Scan {
    Vec2 origin{0.0, 0.0};
    std::span<const Vec2> hits;
    Costmap::Beams beams;
  };
  /// One step at `now` for the robot at `pose` (the localization's estimate) moving at
  /// `velocity` (robot frame, odometry); `scan` is a new laser scan or nullptr. Returns the
  /// velocity command (robot frame): the controller's, held between controller cycles.
  VelocityCommand update(core::SimTime now, const Pose2D& pose, const VelocityCommand& velocity,
                         const Scan* scan);

  const NavStatus& status() const { return status_; }
  MoveBaseState state() const { return state_; }
  const MoveBaseStats& stats() const { return stats_; }
  const Pose2D& goal() const { return goal_; }
  /// The global plan being followed (empty before the first plan).
  const Path& path() const { return plan_; }
  const Costmap& global_costmap() const { return global_; }
  const Costmap& local_costmap() const { return local_; }
  /// Totals over every navigation of this navigator.
  const MoveBaseStats& totals() const { return totals_; }

 private:
  struct Traj {
    double vx = 0.0, vy = 0.0, vth = 0.0;
    double cost = -1.0;
    double end_x = 0.0, end_y = 0.0, end_th = 0.0;
  };
  void finish(NavOutcome outcome, std::string message);
  void new_goal(core::SimTime now);
  bool make_plan(const Pose2D& pose);
  bool compute_velocity(const Pose2D& pose, const VelocityCommand& vel, VelocityCommand& cmd);
  void update_grids(const Pose2D& pose);
  Traj create_trajectories(const Pose2D& pose, const VelocityCommand& vel);
  void generate(const Pose2D& pose, const VelocityCommand& vel, double vx_s, double vy_s,
                double vth_s, Traj& t) const;
  // generate()'s headings depend only on the start heading, the turn rate, the sampled turn rate
  // and the number of steps: their cosines and sines, step by step, kept for the other samples
  // of the same controller cycle (the trigonometry was a third of a rollout's cost).
  struct TrigRun {
    std::uint64_t vth_s_bits = 0;
    int steps = 0;
    std::vector<double> cos_th, sin_th;  // at step 0, 1, ... as far as a rollout went
  };
  mutable std::vector<TrigRun> trig_runs_;
  mutable std::size_t trig_used_ = 0;
  mutable std::uint64_t trig_theta_bits_ = 0, trig_omega_bits_ = 0;
  mutable double trig_cos0_ = 1.0, trig_sin0_ = 0.0;
  TrigRun& trig_run(const Pose2D& pose, const VelocityCommand& vel, double vth_s, int steps) const;
  bool rotation_free(const Pose2D& pose) const;
  void start_recovery(core::SimTime now, const Pose2D& pose);
  VelocityCommand run_recovery(core::SimTime now, const Pose2D& pose);
  VelocityCommand approach(const Pose2D& pose);
  VelocityCommand straight_to(const Pose2D& pose, const Pose2D& target, double speed,
                              double tolerance_m, double tolerance_rad, bool& arrived) const;
  void add_stats(double dt);

  const Planner* planner_;
  MoveBaseConfig config_;
  Costmap global_;
  Costmap local_;
  NavStatus status_;
  MoveBaseState state_ = MoveBaseState::kIdle;
  MoveBaseStats stats_;
  MoveBaseStats totals_;
  Pose2D goal_;       // what the caller asked for
  Pose2D base_goal_;  // what move_base drives to now (a graph node, or final_goal_)
  bool needs_approach_ = false;
  Pose2D final_goal_;  // the last move_base goal (the approach pose if one is needed)
  bool final_needs_approach_ = false;
  // ppgoto's route: graph nodes, then the final target (final_goal_), each with the distance
  // at which it counts as reached.
  struct Waypoint {
    Pose2D pose;
    double tolerance = 0.4;
  };
  std::vector<Waypoint> route_;
  std::size_t route_next_ = 0;
  bool route_built_ = false;
  bool target_reached_ = false;
  core::SimTime target_reached_at_;
  core::SimTime sent_at_;
  void build_route(core::SimTime now, const Pose2D& pose);
  void send_goal(core::SimTime now, const Pose2D& pose);
  bool route_step(core::SimTime now, const Pose2D& pose);
  void route_done(const Pose2D& pose);
  void give_up(NavOutcome outcome, std::string message);
  bool depart_checked_ = false;
  bool forward_ = false;  // carrying a puck: the departure turns first, never backs off
  Pose2D depart_to_;      // where the departure move goes
  Path plan_;
  // Times.
  core::SimTime last_update_;
  bool has_last_update_ = false;
  core::SimTime next_control_;
  core::SimTime next_local_;
  core::SimTime next_global_;
  core::SimTime last_valid_plan_;
  core::SimTime last_valid_control_;
  VelocityCommand command_;
  // Latest scan, kept until the costmaps have used it.
  std::vector<Vec2> scan_hits_;
  std::vector<int> scan_beam_of_hit_;
  Costmap::Beams scan_beams_;  // (of_hit empty: scan_beam_of_hit_ holds it)
  Costmap::Beams scan_beams() const {
    Costmap::Beams b = scan_beams_;
    b.of_hit = scan_beam_of_hit_;
    return b;
  }
  Vec2 scan_origin_{0.0, 0.0};
  bool scan_for_local_ = false;
  bool scan_for_global_ = false;
  // Recovery.
  enum class Trigger { kPlanning, kControlling };
  Trigger trigger_ = Trigger::kPlanning;
  int recovery_index_ = 0;
  bool rotating_ = false;
  double rotate_start_offset_ = 0.0;
  bool rotate_got_180_ = false;
  // Rollout controller's grids, the local costmap's cells with a one-cell frame around them
  // (row length grid_w_; cell (i, j) at grid_index()), and memory.
  std::vector<int> path_dist_;
  std::vector<int> goal_dist_;
  std::vector<int> grid_init_;  // update_grids(): the grids before a search
  std::vector<int> queue_;
  int grid_w_ = 0;
  int unreachable_ = 0;
  std::size_t grid_index(int i, int j) const {
    return static_cast<std::size_t>(j + 1) * static_cast<std::size_t>(grid_w_) +
           static_cast<std::size_t>(i + 1);
  }
  bool rotating_to_goal_ = false;
  bool stuck_left_ = false, stuck_right_ = false;
  bool stuck_left_strafe_ = false, stuck_right_strafe_ = false;
  bool rotating_left_ = false, rotating_right_ = false;
  bool strafe_left_ = false, strafe_right_ = false;
  bool escaping_ = false;
  double prev_x_ = 0.0, prev_y_ = 0.0;
  double escape_x_ = 0.0, escape_y_ = 0.0, escape_th_ = 0.0;
  std::size_t prune_from_ = 0;
  // Navfn memory.
  std::vector<float> potential_;
  std::vector<std::uint8_t> done_;
};

}  // namespace llsf::planner
