// The expert of the five ManiSoft tasks (paper section 3.4: a rule-based planner per task whose
// SE(3) waypoints and gripper states are tracked by the model executor).
//
//   task::Expert expert(env);       // env: a task::TaskEnv
//   env.reset(spec);  expert.reset();
//   while (!env.done()) { expert.act(torques, S); env.step(torques, S); }
//
// Planner: every task is a list of moves "put object i at pose P" (asset frame -> world):
//   COLL  the object into the container: its bottom place_clearance above the rim, lowered on
//         into it as far as the fingertips stay finger_clearance above the rim (down to the
//         floor when the open gripper fits into the opening: the basket);
//   ALN   the object at the goal pose (the symmetric equivalent nearest its current yaw);
//   STK   items[k] onto items[k-1] for k = 1, 2, ... (on the receptacle of the item below, or on
//         its top), the item below read when the move starts; released with the fingertips
//         stack_finger_clearance above the item below's top (the item drops the rest);
//   ARR   each relation's object at the free spot the scene gives for it (Relation::spots);
//   OVR   the object at the marker's position as it stands (the "via" carry lifts it over the
//         obstacle between: corridor_top).
// Orientation: kept as the object stands (translation only) except ALN's yaw.
// Grasp: among the asset's annotated grasps, each also turned half a turn about the fingers' axis
// (the parallel gripper is symmetric) and turned about the object's axis as its symmetry allows
// (round: eighth turns, square: quarter turns), the one whose grasp and place end-effector poses
// turn least from the home pose, whose whole sequence the executor accepts (continuous shapes
// within the actuation limits, the payload included), whose waypoint shapes keep every rod
// node table_clearance above the table top, and along whose lines (line_samples shapes each)
// the rod keeps arm_clearance from the bounding box of every obstacle and every object but the
// moved one (arm_clear); along the carry lines the held object's and the open gripper's boxes
// keep held_clearance from the other objects' and obstacles' boxes, except those they cannot
// avoid at the grasp or the place (held_clear). Each candidate grasp comes with seven leg
// variants: the approach and the carry each direct or "via" (below), and the via ones again with
// their via points raised by via_raise (tried after the others of that grasp: over what the lower
// lines would sweep the arm through). No detour around an obstacle is planned: a move with no
// clear candidate is given up.
// Waypoints of a move (the end-effector frame; straight lines with quintic timing, or a cruise
// at constant speed over path_cruise of the line: ModelExecutor::track_line): approach (along
// the annotation's approach direction, approach_distance from the grasp; "via": first to above
// it, for a tall object high enough that the fingertips pass approach_tip_clearance above its top,
// and higher while the line there would still sweep them into it; candidates whose approach would
// sweep the open fingers into a tall object come last: approach_clear()), grasp (at tight_peak_speed when the grasp is tight: tight_clearance), close once settled
// (the arm's tip slower than settle_speed), carry (above the place pose, diagonal from the grasp;
// "via": first straight up by lift_height, or until the object's bottom is 2 x held_clearance
// above every other object and obstacle near its course: corridor_top), place (corrected for
// where the object sits in the hand, measured when it is held, with the target orientation's
// symmetric equivalent nearest the held one; the corrected carry is checked again and, when
// refused, the other kind of carry tried), lowered once the arm's tip is slower than
// carry_settle_speed: at lower_peak_speed, a long lower (into a container) at the carry's speed
// until slow_lower above its end first, open once settled or as soon as the support carries the object or the
// gripper touches anything else (the closed fingers on a bowl below: fingers_blocked) (a tall
// one, height above tall_ratio x width, is lowered on until its support carries it, contact_depth
// below, so it is not dropped onto its rim; the arm stops there, release_lift up, and opens once
// its tip is slower than release_settle_speed), then (a tall one: once the opening fingers clear
// it by release_clearance on each side; fingers still on it drag it along as the arm sways, and
// it tips over) up at retract_peak_speed until the fingertips clear the object's top (after
// the last move too). A
// leg whose straight line would pass towards the inner edge of the arm's reach (arc_inset nearer
// its base than its farther end) goes round an arc point about the base instead. A missed grasp
// re-opens and retries the move from its approach (max_retries); so does, backing off along its
// approach with the gripper open, a descent that ends grasp_error short of its grasp or a grasp
// whose carry no longer passes from where the object sits in the hand, the move then planned
// without that grasp. The executor's stiffness estimate is frozen while the tool may touch
// something (descend, close, lower, open: ModelExecutor::freeze_estimate).
// Refused lines: the candidates are first checked with straight lines only; when none passes,
// again with each refused approach or carry line replaced by the executor's shape ramp to the
// pose's cold inverse statics solution (ModelExecutor::set_target; ramp_fallback; not on a
// re-try), when that is within the limits and clear of the table (the ramp's intermediate shapes
// are not checked). A
// line the executor refuses while running (it starts from where the arm's shape target is, not
// the planned pose) also falls back to a ramp.
// Deterministic; allocation only when a move is planned, its carry re-checked at the grasp or a
// ramp set up (path set-ups copy the executor).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "manisoft/control/arm_observation.hpp"
#include "manisoft/control/model_executor.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/geometry/box_overlap.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/task/moves.hpp"
#include "manisoft/task/registry.hpp"
#include "manisoft/task/task_env.hpp"

namespace manisoft::task {

struct ExpertConfig {
  double carry_height = 0.05;       ///< m: end-effector above the place pose before lowering
  double lift_height = 0.06;        ///< m: straight up from the grasp first (a "via" carry)
  double via_raise = 0.1;           ///< m: the high variants of a grasp (tried after its others) raise their via points this much
  double place_clearance = 0.008;   ///< m: the object's bottom above its support when released
  double retract_height = 0.06;     ///< m: up after every release (at least)
  double finger_clearance = 0.02;   ///< m: and until the fingertips are this far above the released object's top
  double stack_finger_clearance = 0.0;  ///< m: STK: the lower stops with the fingertips this far above the item below's top (lower_goal)
  double path_peak_speed = 1.5;     ///< m/s, peak end-effector speed of a path's quintic timing (gripper empty)
  double max_node_speed = 1.5;      ///< m/s, planned peak speed of any rod node (gripper empty)
  double carry_peak_speed = 1.5;    ///< m/s, the same while an object is held (its acceleration bounded by carry_grip_share)
  double carry_node_speed = 1.5;    ///< m/s
  double carry_grip_share = 0.45;   ///< a held line's planned peak acceleration at most this share of what the grip holds (max_hold_force / mass; 0: not bounded): a short lift at the carry's full speed can accelerate a tall object past what the grip holds
  double path_cruise = 0.7;         ///< fraction of a path at constant speed (0: quintic timing; ModelExecutor::track_line)
  int min_segment_steps = 60;       ///< shortest path, control steps
  double settle_speed = 0.15;       ///< m/s: close / open only when the arm's tip is slower
  double settle_error = 0.01;       ///< m: and the end-effector this near its pose
  int max_settle_steps = 200;       ///< longest wait for settling (then act anyway)
  double release_settle_speed = 0.05;  ///< m/s: once the support carries a tall object, stop and open only when the arm's tip is slower (0: open at once)
  double tall_ratio = 1.2;          ///< an object is tall (release_settle_speed) above this height / width
  double release_lift = 0.0;        ///< m: the stop above where the arm is (release_settle_speed)
  double release_clearance = 0.01;  ///< m: the retract from a tall object waits until the opening fingers clear it by this much on each side (or are fully open)
  double contact_depth = 0.001;     ///< m: a tall object is lowered until its support carries it: its lower line ends this far below its support (deeper presses it on, and it rocks on its base after the release)
  double retract_peak_speed = 0.9;  ///< m/s: peak end-effector speed of the retract after a release
  double lower_peak_speed = 0.3;    ///< m/s: peak end-effector speed of the lower line
  double slow_lower = 0.03;         ///< m: a lower line longer than twice this runs at the carry's speed until this far above its end (0: all slow)
  double approach_tip_clearance = 0.02;  ///< m: a tall object's approach keeps the open fingertips this far above its top until they straddle it
  double carry_settle_speed = 0.1;  ///< m/s: lower only once the arm's tip is slower at the end of the carry (0: at once)
  double tight_clearance = 0.015;   ///< m: a grasp is tight when the open fingers clear the object by less on each side: descend to it at tight_peak_speed
  double tight_peak_speed = 0.6;    ///< m/s: peak end-effector speed of the descent to a tight grasp
  double start_error = 0.03;       ///< m: a chained path starts once the previous one is this near
  double via_error = 0.05;          ///< m: the same at a leg's arc or via point (the next line starts from the shape target; the arm catches up)
  double table_clearance = 0.03;    ///< m: every rod node of a waypoint shape above the table top
  double arm_clearance = 0.01;      ///< m: the rod's surface clear of the other objects' and obstacles' boxes along planned lines
  double held_clearance = 0.01;     ///< m: the held object's and the open gripper's boxes clear of theirs along the carry
  bool check_arm_clearance = true;  ///< false: lines are not checked against objects and obstacles (for measuring the check)
  double arc_inset = 0.03;          ///< m: a straight leg this much nearer the base than its farther end goes round an arc point
  int max_retries = 1;              ///< re-tries of a move whose grasp failed (missed, blocked or not carriable), each with another grasp
  double grasp_error = 0.02;        ///< m: a descent that ends farther than this from its grasp pose (a finger on the object) backs off and re-tries
  double approach_distance = 0.06;  ///< m: the approach pose this far from the grasp, along the annotation's approach direction
  bool ramp_fallback = true;        ///< a refused line may be replaced by a shape ramp
  bool freeze_estimate_in_contact = true;  ///< the executor's stiffness estimate is frozen while the tool may touch things (descend, close, lower, open)

  /// Refuses a value out of its range, naming the field (speeds and errors > 0, distances >= 0).
  void validate() const {
    using manisoft::detail::require_non_negative;
    using manisoft::detail::require_positive;
    for (const auto& [name, v] : {std::pair{"carry_height", carry_height}, {"lift_height", lift_height}, {"via_raise", via_raise},
                                  {"place_clearance", place_clearance}, {"retract_height", retract_height},
                                  {"finger_clearance", finger_clearance}, {"stack_finger_clearance", stack_finger_clearance},
                                  {"carry_grip_share", carry_grip_share}, {"release_settle_speed", release_settle_speed},
                                  {"release_lift", release_lift}, {"release_clearance", release_clearance}, {"contact_depth", contact_depth}, {"slow_lower", slow_lower},
                                  {"approach_tip_clearance", approach_tip_clearance}, {"carry_settle_speed", carry_settle_speed},
                                  {"tight_clearance", tight_clearance}, {"table_clearance", table_clearance},
                                  {"arm_clearance", arm_clearance}, {"held_clearance", held_clearance}, {"arc_inset", arc_inset}}) {
      require_non_negative((std::string("ExpertConfig ") + name).c_str(), v);
    }
    for (const auto& [name, v] : {std::pair{"path_peak_speed", path_peak_speed}, {"max_node_speed", max_node_speed},
                                  {"carry_peak_speed", carry_peak_speed}, {"carry_node_speed", carry_node_speed},
                                  {"settle_speed", settle_speed}, {"settle_error", settle_error}, {"tall_ratio", tall_ratio},
                                  {"retract_peak_speed", retract_peak_speed}, {"lower_peak_speed", lower_peak_speed},
                                  {"tight_peak_speed", tight_peak_speed}, {"start_error", start_error}, {"via_error", via_error},
                                  {"grasp_error", grasp_error}, {"approach_distance", approach_distance}}) {
      require_positive((std::string("ExpertConfig ") + name).c_str(), v);
    }
    if (!(path_cruise >= 0 && path_cruise <= 0.95)) manisoft::detail::fail("ExpertConfig path_cruise = ", path_cruise, " is invalid: it must be in [0, 0.95]");
    if (min_segment_steps < 1 || max_settle_steps < 0 || max_retries < 0) {
      manisoft::detail::fail("ExpertConfig min_segment_steps = ", min_segment_steps, " (>= 1), max_settle_steps = ", max_settle_steps,
                             " (>= 0), max_retries = ", max_retries, " (>= 0): out of range");
    }
  }
};

/// What the expert is doing.
enum class ExpertPhase { approach, descend, close, carry, lower, open, retract, idle, failed };

inline std::string_view to_string(ExpertPhase p) {
  switch (p) {
    case ExpertPhase::approach: return "approach";
    case ExpertPhase::descend: return "descend";
    case ExpertPhase::close: return "close";
    case ExpertPhase::carry: return "carry";
    case ExpertPhase::lower: return "lower";
    case ExpertPhase::open: return "open";
    case ExpertPhase::retract: return "retract";
    case ExpertPhase::idle: return "idle";
    case ExpertPhase::failed: return "failed";
  }
  return "?";
}

/// A waypoint reached (or a phase entered) at a control step.
struct ExpertEvent {
  long step = 0;
  int move = 0;
  ExpertPhase phase = ExpertPhase::approach;
  Eigen::Vector3d position{Eigen::Vector3d::Zero()};  ///< end-effector position when it happened
};

class Expert {
 public:
  using Pose = math::Pose<double>;
  using Vec3 = Eigen::Vector3d;
  using Array3 = TaskEnv::Array3;
  using Executor = TaskEnv::Executor;

  explicit Expert(const TaskEnv& env, ExpertConfig config = {})
      : env_(&env), config_(config), executor_(env.home_executor()), planner_(env.home_executor()), planner_backup_(env.home_executor()),
        arm_margin_(std::sqrt(env.arm_model().rod.cross_section_area.maxCoeff() / std::numbers::pi) + config.arm_clearance) {
    config_.validate();
    const int n = env.arm_model().rod.n_elements;
    observation_ = control::make_arm_observation<double>(n, env.config().observe_stride);
    const auto& gp = env.gripper_parameters();
    gripper_half_ = Vec3(std::max(gp.palm_half_x, 0.5 * gp.open_width + gp.finger_thickness), std::max(gp.palm_half_y, gp.finger_half_width),
                         0.5 * (gp.palm_thickness + gp.finger_length));
    gripper_center_ = Vec3(0, 0, gripper_half_.z());
    events_.reserve(64);
    excluded_.reserve(8);
  }

  /// Starts the episode of the env's current scene (call after env.reset()).
  void reset() {
    executor_ = env_->home_executor();
    target_ = env_->home_pose();
    move_ = 0;
    retries_ = 0;
    excluded_.clear();
    s_ = 0;
    waited_ = 0;
    touched_ = false;
    lower_fast_ = false;
    steps_ = 0;
    events_.clear();
    failure_.reset();
    moves_ = count_moves();
    begin_move();
  }

  /// The action of the next control step (torques n x 3 and gripper state S), from the env's
  /// privileged state. Call once per env.step().
  void act(Array3& torques, int& s) {
    const auto& w = env_->world();
    if (steps_ > 0) advance(w);
    control::observe_arm(w, target_, observation_);
    executor_.act(observation_, torques);
    s = s_;
    ++steps_;
  }

  ExpertPhase phase() const { return phase_; }
  int move() const { return move_; }
  int moves() const { return moves_; }
  /// Why the expert gave up (none while it has not): a path the executor refused, a missed grasp.
  /// The text lives as long as the expert, until its next reset().
  std::optional<std::string_view> failure() const { return failure_; }
  const std::vector<ExpertEvent>& events() const { return events_; }
  const Executor& executor() const { return executor_; }

 private:
  /// One move: the object, where it goes, and the end-effector waypoints. A leg is one or two
  /// straight lines: direct, or "via" (approach: level to above the approach pose first; carry:
  /// straight up by lift_height first, then level to above the place pose).
  /// The lines of a leg, in order; a "ramp" line is the executor's shape ramp to the pose's cold
  /// inverse statics solution instead of a straight line (the fallback of a refused line).
  struct Leg {
    std::array<Pose, 4> pose;
    std::array<bool, 4> ramp{};
    int count = 0;
    void clear() { count = 0; }
    void push(const Pose& p) { pose[static_cast<std::size_t>(count)] = p, ramp[static_cast<std::size_t>(count)] = false, ++count; }
  };
  struct Plan {
    int object = -1;
    Pose object_target;  ///< asset frame -> world at release
    Pose grasp, place;   ///< end-effector poses
    double width = 0;    ///< m, the object's width between the fingers (the grasp annotation's)
    double sink = 0;     ///< m the object is lowered into a container below its rim (COLL)
    bool via_approach = false, via_carry = false;
    double raise = 0;  ///< m: the via points this much higher (the high variants)
    Pose start;  ///< the end-effector pose the approach leg starts from
    Leg approach_leg, carry_leg;
  };

  /// Appends `to` to a leg, after an arc point when the straight line from `from` would pass
  /// arc_inset closer to the arm's base (horizontally) than its farther end: the arm reaches an
  /// annulus about its base, and a chord cuts towards its inner edge. The arc point: the farther
  /// end's distance from the base at the ends' mean bearing, the higher end's height, the
  /// orientations' midway.
  void append_leg(Leg& leg, const Pose& from, const Pose& to) const {
    const Eigen::Vector2d base = env_->spec().arm_mount.base_position.head<2>();
    const Eigen::Vector2d a = from.translation.head<2>() - base, b = to.translation.head<2>() - base, ab = b - a;
    const double t = ab.squaredNorm() > 1e-12 ? std::clamp(-a.dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    if ((a + t * ab).norm() < std::max(a.norm(), b.norm()) - config_.arc_inset) {
      const double r = std::max(a.norm(), b.norm());
      const double bearing = std::atan2(a.y(), a.x()) + 0.5 * std::remainder(std::atan2(b.y(), b.x()) - std::atan2(a.y(), a.x()), 2 * std::numbers::pi);
      Pose via;
      via.translation << base + r * Eigen::Vector2d(std::cos(bearing), std::sin(bearing)), std::max(from.translation.z(), to.translation.z());
      via.rotation = Eigen::Quaterniond(from.rotation).slerp(0.5, Eigen::Quaterniond(to.rotation)).toRotationMatrix();
      leg.push(via);
    }
    leg.push(to);
  }

  /// The annotation's approach pose moved to approach_distance from its grasp (same direction).
  Pose approach_pose(const assets::GraspAnnotation& g) const {
    Pose a = g.approach;
    const Vec3 d = g.approach.translation - g.grasp.translation;
    if (d.norm() > 1e-9) a.translation = g.grasp.translation + config_.approach_distance * d.normalized();
    return a;
  }

  /// Where the fingertips are (world) at end-effector pose `p`.
  Vec3 fingertips(const Pose& p) const {
    const auto& gp = env_->gripper_parameters();
    return p.act(Vec3(0, 0, gp.palm_thickness + gp.finger_length));
  }
  /// Height (world z) of object i's top as it stands now.
  double top_of(int object) const { return state_of(object).pose.act(Vec3(0, 0, scene::asset_height(asset_of(object)))).z(); }

  /// The approach leg from the end-effector pose `from` (the annotation's approach pose last).
  /// "via": to above the approach pose first, then straight down; for a tall object (is_tall())
  /// high enough that the fingertips pass approach_tip_clearance above its top, and raised by
  /// another approach_raise_step (up to approach_raise_steps times) while the line there would
  /// still bring the open fingers into its reach (approach_clear(): a line that climbs from a
  /// lower start enters that reach before it is high enough). Returns approach_clear() of the leg.
  bool set_approach_leg(Plan& p, const Pose& approach, const Pose& from) const {
    p.start = from;
    Pose above = approach;
    above.translation.z() = std::max(approach.translation.z(), from.translation.z()) + p.raise;
    const bool tall = p.via_approach && is_tall(p.object);
    if (tall)
      above.translation.z() = std::max(above.translation.z(), approach.translation.z() + top_of(p.object) + config_.approach_tip_clearance - fingertips(approach).z());
    for (int raise = 0;; ++raise) {
      p.approach_leg.clear();
      Pose prev = from;
      if (p.via_approach) {
        append_leg(p.approach_leg, prev, above);
        prev = above;
      }
      append_leg(p.approach_leg, prev, approach);
      const bool clear = approach_clear(p);
      if (clear || !tall || raise == approach_raise_steps) return clear;
      above.translation.z() += approach_raise_step;
    }
  }
  /// Whether the approach leg keeps the open fingers off a tall object (is_tall(); a low one
  /// does not tip over): sampled along each line (positions linear, the line's end orientation),
  /// wherever the fingertips are lower than approach_tip_clearance above its top, the gripper's
  /// axis is either over it (it is between the fingers whichever way they turn), out of the
  /// fingers' reach of it, or where it is at the approach pose (the straight descent onto the
  /// annotated grasp, which straddles the object as annotated, also when its footprint's
  /// circumscribed circle is wider than the opening).
  bool approach_clear(const Plan& p) const {
    if (!is_tall(p.object)) return true;
    const auto& gp = env_->gripper_parameters();
    const double r = scene::footprint_radius(asset_of(p.object)), top = top_of(p.object);
    const Eigen::Vector2d axis = state_of(p.object).pose.translation.head<2>();
    const double between = 0.5 * gp.open_width - r;
    const double reach = r + std::hypot(0.5 * gp.open_width + gp.finger_thickness, gp.finger_half_width);
    constexpr int samples = 16;
    constexpr double straddle = 0.005;  // m: fingertips this near (horizontally) to where they are at the approach pose
    const Eigen::Vector2d last = fingertips(p.approach_leg.pose[static_cast<std::size_t>(p.approach_leg.count - 1)]).head<2>();
    Pose prev = p.start;
    for (int i = 0; i < p.approach_leg.count; ++i) {
      const Pose& to = p.approach_leg.pose[static_cast<std::size_t>(i)];
      for (int k = 1; k <= samples; ++k) {
        Pose x = to;
        x.translation = prev.translation + (double(k) / samples) * (to.translation - prev.translation);
        const Vec3 tips = fingertips(x);
        const double d = (tips.head<2>() - axis).norm();
        if (tips.z() < top + config_.approach_tip_clearance && d > between && d < reach && (tips.head<2>() - last).norm() > straddle) return false;
      }
      prev = to;
    }
    return true;
  }

  /// Into a container (SupportKind::into: COLL): the object is released low in the container
  /// (its bottom place_clearance above the floor) rather than dropped from above the rim (a tall
  /// one dropped inner_depth rocks on in the container for seconds), as far as the fingertips
  /// stay finger_clearance above the rim, or down to the floor when the open gripper fits into
  /// the opening (a basket). move_goal() puts the object's bottom place_clearance above the rim;
  /// this lowers it.
  void sink_into_container(Plan& p, const Support& support) const {
    if (support.kind != SupportKind::into) return;
    const auto& rc = asset_of(support.object).receptacles.at(0);
    // A container whose opening the open gripper fits into (finger_clearance to spare, at any
    // yaw): the object goes down to its floor.
    const double reach = std::hypot(gripper_half_.x(), gripper_half_.y());
    const double room = rc.inner_radius > 0 ? rc.inner_radius : rc.inner_half_extents.minCoeff();
    const double rim = (state_of(support.object).pose * rc.opening).translation.z();
    p.sink = room >= reach + config_.finger_clearance ? rc.inner_depth
                                                        : std::clamp(fingertips(p.place).z() - (rim + config_.finger_clearance), 0.0, rc.inner_depth);
    p.place.translation.z() -= p.sink;
    p.object_target.translation.z() -= p.sink;
  }

  /// The carry leg from the grasp to carry_height (plus the sink) above the place pose.
  void set_carry_leg(Plan& p) const {
    Pose above = p.place;
    above.translation.z() += config_.carry_height + p.sink;
    p.carry_leg.clear();
    Pose prev = p.grasp;
    if (p.via_carry) {
      Pose lift = p.grasp;
      lift.translation.z() += std::max(config_.lift_height, corridor_top(p) + 2 * config_.held_clearance - state_of(p.object).pose.translation.z()) + p.raise;
      above.translation.z() = std::max(above.translation.z(), lift.translation.z());
      append_leg(p.carry_leg, prev, lift);
      prev = lift;
    }
    append_leg(p.carry_leg, prev, above);
  }

  /// The highest top (world z) of the other objects and obstacles near the carry's course from
  /// the grasp to the place (the straight line or, at the edge of the reach, its arc point:
  /// append_leg), horizontally within their footprint radius plus the moved object's plus
  /// held_clearance; the table top when there are none.
  double corridor_top(const Plan& p) const {
    Leg course;
    append_leg(course, p.grasp, p.place);
    const double r = scene::footprint_radius(asset_of(p.object)) + config_.held_clearance;
    auto near = [&](const Pose& pose, const assets::Asset& asset) {
      const Eigen::Vector2d c = pose.act(asset.bounding_center).head<2>();
      Eigen::Vector2d a = p.grasp.translation.head<2>();
      for (int i = 0; i < course.count; ++i) {
        const Eigen::Vector2d b = course.pose[static_cast<std::size_t>(i)].translation.head<2>(), ab = b - a;
        const double t = ab.squaredNorm() > 1e-12 ? std::clamp((c - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
        if ((a + t * ab - c).norm() < scene::footprint_radius(asset) + r) return true;
        a = b;
      }
      return false;
    };
    auto top = [](const Pose& pose, const assets::Asset& asset) { return pose.act(asset.bounding_center).z() + asset.bounding_half_extents.z(); };
    const auto& s = env_->spec();
    double z = s.table.top_center.z();
    for (std::size_t i = 0; i < s.objects.size(); ++i) {
      const int o = static_cast<int>(i);
      if (o != p.object && near(state_of(o).pose, asset_of(o))) z = std::max(z, top(state_of(o).pose, asset_of(o)));
    }
    for (const auto& o : s.obstacles) {
      const auto& asset = env_->library().get(o.asset_id, "expert obstacle");
      if (near(o.pose, asset)) z = std::max(z, top(o.pose, asset));
    }
    return z;
  }

  int count_moves() const {
    const auto& s = env_->spec();
    return visit_task(s.task, [&s]<TaskType T>(T) { return T::moves(s); });
  }

  const assets::Asset& asset_of(int object) const {
    return env_->library().get(env_->spec().objects.at(static_cast<std::size_t>(object)).asset_id, "expert object");
  }
  const ObjectState& state_of(int object) const { return env_->snapshot().objects[static_cast<std::size_t>(object)]; }

  /// Move k: which object goes where (read from the current state; the task type's move()).
  Move move_goal(int k) const {
    const Snapshot snapshot = env_->snapshot();
    const MoveScene scene{env_->spec(), env_->library(), snapshot, config_.place_clearance};
    return visit_task(env_->spec().task, [&]<TaskType T>(T) { return T::move(k, scene); });
  }

  /// What move k puts its object into or onto (COLL: the container, STK: the item below; -1: the
  /// table): the carry keeps clear of it until it lowers the object.
  Support support_of(int k) const {
    const auto& s = env_->spec();
    return visit_task(s.task, [&]<TaskType T>(T) { return T::support(k, s); });
  }

  /// Whether the yaw of the object's target pose is free: the object is round, or the task
  /// states no orientation (states_yaw).
  bool yaw_free(int object) const {
    const bool states_yaw = visit_task(env_->spec().task, []<TaskType T>(T) { return T::states_yaw; });
    return !states_yaw || scene::asset_symmetry(asset_of(object)).kind == scene::Symmetry::Kind::axial;
  }

  /// Angle between an end-effector orientation and the home one.
  double turn_from_home(const Pose& p) const { return Eigen::AngleAxisd(p.rotation * env_->home_pose().rotation.transpose()).angle(); }

  /// A grasp candidate of a move and its cost (least turning first, then the fewest lines).
  struct Candidate {
    double cost;
    Plan plan;
  };

  /// The grasp of move k: the feasible candidate that turns least (see the header comment).
  bool plan_move(int k) {
    const auto [object, target] = move_goal(k);
    const std::vector<Candidate> candidates = grasp_candidates(object, target, support_of(k));
    plan_refusal_ = candidates.empty() ? "the asset has no grasp annotation" : "";
    // first pass: straight lines only; second: refused lines repaired (check_leg)
    plan_object_ = object;
    for (int pass = 0; pass < 2; ++pass) {
      repair_ = pass == 1;
      // (a re-try, whose first grasp failed, searches straight lines only: the repair pass checks
      // every candidate again, about 0.5 s when none passes)
      if (repair_ && (!config_.ramp_fallback || retries_ > 0)) break;
      for (auto c : candidates) {
        if (check_candidate(c.plan, k)) {
          plan_ = c.plan;
          return true;
        }
      }
    }
    return false;
  }

  /// Every grasp candidate of putting `object` at `target`, cheapest first: each annotated grasp
  /// turned about the object's axis as its symmetry allows (round: eighth turns, square: quarter
  /// turns) and half a turn about the fingers' axis (the parallel gripper), each with seven leg
  /// variants; grasps a re-try left out are not among them.
  std::vector<Candidate> grasp_candidates(int object, const Pose& target, const Support& support) const {
    const auto& a = asset_of(object);
    const Pose now = state_of(object).pose;
    std::vector<Candidate> candidates;
    const Pose from = executor_.statics().desired_tip_pose();
    const scene::Symmetry sym = scene::asset_symmetry(a);
    const int object_turns = sym.kind == scene::Symmetry::Kind::axial ? 8 : sym.kind == scene::Symmetry::Kind::discrete ? std::max(1, sym.order) : 1;
    for (const auto& g : a.grasps) {
      for (int t = 0; t < object_turns; ++t) {
        Pose about_axis;
        about_axis.rotation = Eigen::AngleAxisd(2 * std::numbers::pi * t / object_turns, Vec3::UnitZ()).toRotationMatrix();
        for (int flip = 0; flip < 2; ++flip) {
          Pose half;
          half.rotation = Eigen::AngleAxisd(flip * std::numbers::pi, Vec3::UnitZ()).toRotationMatrix();
          for (int variant = 0; variant < 8; ++variant) {
            if (variant == 4) continue;  // raised with no via point: the same as variant 0
            Plan p;
            p.object = object;
            p.object_target = target;
            p.width = g.width;
            p.grasp = now * about_axis * g.grasp * half;
            if (excluded(now, p.grasp)) continue;
            p.place = target * now.inverse() * p.grasp;
            sink_into_container(p, support);
            p.via_approach = variant & 1;
            p.via_carry = variant & 2;
            p.raise = variant & 4 ? config_.via_raise : 0.0;
            const bool clear = set_approach_leg(p, now * about_axis * approach_pose(g) * half, from);
            set_carry_leg(p);
            // least turning first, then the fewest lines
            // (approaches that would sweep the fingers into a tall object last)
            const double cost = std::max(turn_from_home(p.grasp), turn_from_home(p.place)) + 1e-3 * variant + (clear ? 0.0 : 10.0);
            candidates.push_back({cost, p});
          }
        }
      }
    }
    std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) { return x.cost < y.cost; });
    return candidates;
  }

  /// Checks candidate plan p of move k on planner_ from the executor's shape target: approach,
  /// grasp, carry (holding the object), place. False (the first refusal noted in plan_refusal_)
  /// when a line is refused.
  bool check_candidate(Plan& p, int k) {
    const auto& a = asset_of(p.object);
    const Pose now = state_of(p.object).pose;
    planner_ = executor_;
    planner_.complete_path();
    const char* why = "";
    const char* where = "";
    bool ok = check_leg(p.approach_leg, why);
    if (!ok) where = "approach";
    if (ok && !(ok = check_line(p.grasp, why))) where = "grasp";
    if (ok) {
      planner_.set_payload(a.mass, p.grasp.rotation.transpose() * (now.act(a.center_of_mass) - p.grasp.translation));
      if (!(ok = check_carry_leg(p, p.grasp, now, support_of(k).object, why))) where = "carry";
    }
    if (ok && !(ok = check_line(p.place, why))) where = "place";
    if (!ok && plan_refusal_.empty()) plan_refusal_ = std::string(where) + ": " + why;
    return ok;
  }

  /// Tracks one line to `to` on planner_ (from its shape target) and jumps to its end; false
  /// (the planner as before, `why` set) when the executor refuses it or its end shape comes
  /// within table_clearance of the table top.
  bool check_line(const Pose& to, const char*& why) {
    planner_backup_ = planner_;
    const Pose from = planner_.statics().desired_tip_pose();
    const auto report = planner_.track_line(to, line_steps((to.translation - from.translation).norm(), check_held_, 0, plan_object_), node_step(check_held_), config_.path_cruise);
    bool clear = report.accepted && held_line_clear(from, to);
    for (int k = 1; k <= line_samples && report.accepted && clear; ++k) {
      planner_.predicted_shape(long(report.steps) * k / line_samples, shape_);
      clear = arm_clear(shape_);
    }
    planner_.complete_path();
    if (!report.accepted || !clear) {
      why = report.accepted ? "the arm would hit an object or obstacle" : report.reason;
      planner_ = planner_backup_;
      return false;
    }
    if (planner_.statics().desired_state().positions.col(2).minCoeff() < env_->spec().table.top_center.z() + config_.table_clearance) {
      why = "the arm would touch the table";
      planner_ = planner_backup_;
      return false;
    }
    return true;
  }

  /// Whether a shape of the arm (every rod node but the tip, which sits in the palm) keeps the
  /// rod's surface arm_clearance clear of the bounding box of every object but the moved one (as
  /// they stand now) and of every obstacle: a node hits a box when, in the box's frame, it is
  /// within the half extents plus the rod radius and clearance on every axis.
  bool arm_clear(const Array3& positions) const {
    if (!config_.check_arm_clearance) return true;
    const auto& s = env_->spec();
    auto hits = [&](const Pose& pose, const assets::Asset& a) {
      for (Eigen::Index j = 0; j + 1 < positions.rows(); ++j) {
        const Vec3 q = pose.inverse_act(Vec3(positions.row(j).transpose())) - a.bounding_center;
        if ((q.cwiseAbs() - a.bounding_half_extents).maxCoeff() < arm_margin_) return true;
      }
      return false;
    };
    for (std::size_t i = 0; i < s.objects.size(); ++i)
      if (static_cast<int>(i) != plan_object_ && hits(state_of(static_cast<int>(i)).pose, asset_of(static_cast<int>(i)))) return false;
    for (const auto& o : s.obstacles)
      if (hits(o.pose, env_->library().get(o.asset_id, "expert obstacle"))) return false;
    return true;
  }

  /// Whether the held object (check_held_: along a carry leg), carried at held_in_ee_ by the
  /// end-effector at fraction u of the straight line from -> to, and the open gripper's box keep
  /// held_clearance clear of the bounding box of every obstacle and every other object but those
  /// they are that near where the carry starts or the object is placed (held_near_: unavoidable;
  /// its support excepted). Oriented boxes, separating axes.
  bool held_clear(const Pose& from, const Pose& to, double u) const {
    if (!check_held_ || !config_.check_arm_clearance) return true;
    Pose ee;
    ee.translation = from.translation + u * (to.translation - from.translation);
    ee.rotation = Eigen::Quaterniond(from.rotation).slerp(u, Eigen::Quaterniond(to.rotation)).toRotationMatrix();
    const auto& s = env_->spec();
    for (std::size_t i = 0; i < s.objects.size(); ++i) {
      const int o = static_cast<int>(i);
      if (o != plan_object_ && !(held_near_ >> i & 1u) && held_near(ee, state_of(o).pose, asset_of(o))) return false;
    }
    for (const auto& o : s.obstacles)
      if (held_near(ee, o.pose, env_->library().get(o.asset_id, "expert obstacle"))) return false;
    return true;
  }
  /// held_clear() at line_samples points of the straight line from -> to.
  bool held_line_clear(const Pose& from, const Pose& to) const {
    for (int k = 1; k <= line_samples; ++k)
      if (!held_clear(from, to, double(k) / line_samples)) return false;
    return true;
  }
  /// Whether the held object's box (held_in_ee_) or the open gripper's box, the end-effector at
  /// `ee`, comes within held_clearance of the bounding box of `asset` at `pose`.
  bool held_near(const Pose& ee, const Pose& pose, const assets::Asset& asset) const {
    return boxes_overlap(ee * held_in_ee_, asset_of(plan_object_), pose, asset, config_.held_clearance) ||
           geometry::boxes_overlap(ee, gripper_center_, gripper_half_, pose, asset.bounding_center, asset.bounding_half_extents, config_.held_clearance);
  }
  /// Checks plan p's carry leg on planner_ (check_leg) with the held object too (held_clear):
  /// the object at `object` when the end-effector is at `ee`, where the carry starts; what it is
  /// near there and at the place pose (but `support`) is not held against it.
  bool check_carry_leg(Plan& p, const Pose& ee, const Pose& object, int support, const char*& why) {
    held_in_ee_ = ee.inverse() * object;
    held_near_ = 0;
    note_held_near(ee);
    note_held_near(p.place, support);
    check_held_ = true;
    const bool ok = check_leg(p.carry_leg, why);
    check_held_ = false;
    return ok;
  }
  /// Marks the objects the held object's or the gripper's box is within held_clearance of with
  /// the end-effector at `ee` (where the carry starts, where the object is placed: unavoidable).
  void note_held_near(const Pose& ee, int except = -1) {
    const auto& s = env_->spec();
    for (std::size_t i = 0; i < s.objects.size() && i < 64; ++i) {
      const int o = static_cast<int>(i);
      if (o != plan_object_ && o != except && held_near(ee, state_of(o).pose, asset_of(o))) held_near_ |= std::uint64_t(1) << i;
    }
  }
  /// Whether the bounding boxes of assets a (at pose pa) and b (at pb) come within `margin` of
  /// each other: no separating axis among the 15 of two oriented boxes.
  static bool boxes_overlap(const Pose& pa, const assets::Asset& a, const Pose& pb, const assets::Asset& b, double margin) {
    return geometry::boxes_overlap(pa, a.bounding_center, a.bounding_half_extents, pb, b.bounding_center, b.bounding_half_extents, margin);
  }
  /// Checks a ramp to `to` on planner_ (the cold inverse statics solution within the limits and
  /// clear of the table) and jumps to its end; false (the planner as before) otherwise.
  bool check_ramp(const Pose& to) {
    // a held object is checked along the straight line (a ramp's own course is not known before it runs)
    if (!held_line_clear(planner_.statics().desired_tip_pose(), to)) return false;
    planner_backup_ = planner_;
    const auto r = planner_.set_target(to);
    planner_.complete_path();
    const auto& end = planner_.statics().desired_state().positions;
    if (r.within_limits && end.col(2).minCoeff() >= env_->spec().table.top_center.z() + config_.table_clearance && arm_clear(end)) return true;
    planner_ = planner_backup_;
    return false;
  }

  /// Checks a leg's lines on planner_; in the repair pass a refused line becomes a shape ramp
  /// when check_ramp() accepts it. False when a line is refused.
  bool check_leg(Leg& leg, const char*& why) {
    for (int i = 0; i < leg.count; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (leg.ramp[k] ? check_ramp(leg.pose[k]) : check_line(leg.pose[k], why)) continue;
      if (!repair_ || !config_.ramp_fallback || !check_ramp(leg.pose[k])) return false;
      leg.ramp[k] = true;
    }
    return true;
  }

  void begin_move() {
    waited_ = 0;
    if (move_ >= moves_) {
      enter(ExpertPhase::idle);
      return;
    }
    if (!plan_move(move_)) {
      plan_refusal_ = "no feasible grasp (the least-turning one: " + plan_refusal_ + ")";
      give_up(plan_refusal_);
      return;
    }
    leg_ = 0;
    enter(ExpertPhase::approach);
    start_leg(plan_.approach_leg, 0);
  }

  void enter(ExpertPhase p) {
    phase_ = p;
    executor_.freeze_estimate(config_.freeze_estimate_in_contact && (p == ExpertPhase::descend || p == ExpertPhase::close ||
                                                                     p == ExpertPhase::lower || p == ExpertPhase::open));
    if (events_.size() < events_.capacity()) {
      ExpertEvent e;
      e.step = steps_;
      e.move = move_;
      e.phase = p;
      e.position = env_->world().soft().end_effector_frame().position;
      events_.push_back(e);
    }
  }
  /// Backs off along the descent to the approach pose (gripper open) and plans the move again
  /// without this grasp (max_retries); false, nothing changed, when no re-try is left.
  bool retry_with_another_grasp() {
    if (retries_ >= config_.max_retries || plan_.object < 0) return false;
    ++retries_;
    s_ = 0;
    excluded_.push_back(state_of(plan_.object).pose.inverse() * plan_.grasp);
    enter(ExpertPhase::retract);
    if (!start_path(plan_.approach_leg.pose[static_cast<std::size_t>(plan_.approach_leg.count - 1)], false)) begin_move();
    return true;
  }
  /// Whether grasp g (end-effector pose, the object at `object`) is one a re-try left out.
  bool excluded(const Pose& object, const Pose& g) const {
    for (const Pose& e : excluded_) {
      const Pose d = object.inverse() * g;
      if ((d.translation - e.translation).norm() < 0.01 && Eigen::AngleAxisd(d.rotation * e.rotation.transpose()).angle() < 0.2) return true;
    }
    return false;
  }

  void give_up(std::string_view why) {
    failure_ = why;
    enter(ExpertPhase::failed);
  }

  /// Starts the path to `goal`; a refused one ends the episode's plan (give_up) when `required`.
  bool start_path(const Pose& goal, bool required = true, double peak_speed = 0) {
    const double distance = (goal.translation - executor_.statics().desired_tip_pose().translation).norm();
    const bool loaded = s_ == 1;
    const int steps = line_steps(distance, loaded, peak_speed, plan_.object);
    const auto report = executor_.track_line(goal, steps, node_step(loaded), config_.path_cruise);
    if (!report.accepted) {
      // the executor's shape ramp to the goal's cold solution instead, when it has one
      if (config_.ramp_fallback && start_ramp(goal)) return true;
      if (required) give_up(report.reason);
      return false;
    }
    target_ = goal;
    return true;
  }

  /// Control steps of a line `distance` long at its peak end-effector speed (`peak_speed`, or
  /// the configured one with the gripper empty or holding), before the node speed bound; holding
  /// object `held`, also within carry_grip_share of what the grip holds.
  int line_steps(double distance, bool loaded, double peak_speed, int held) const {
    const double peak = peak_speed > 0 ? peak_speed : loaded ? config_.carry_peak_speed : config_.path_peak_speed;
    double seconds = Executor::peak_speed_ratio(config_.path_cruise) * distance / peak;
    if (loaded && config_.carry_grip_share > 0 && held >= 0) {
      // the timing's peak acceleration is shape x distance / T^2
      const double shape = Executor::peak_acceleration_ratio(config_.path_cruise);
      const double accel = config_.carry_grip_share * env_->gripper_parameters().max_hold_force / asset_of(held).mass;
      seconds = std::max(seconds, std::sqrt(shape * distance / accel));
    }
    return std::max(config_.min_segment_steps, static_cast<int>(std::ceil(seconds / env_->control_dt())));
  }
  /// The node speed bound of a line, m per control step.
  double node_step(bool loaded) const { return (loaded ? config_.carry_node_speed : config_.max_node_speed) * env_->control_dt(); }

  /// Starts the executor's shape ramp to `goal` (set_target); false (nothing changed but the
  /// executor's target) when the goal has no inverse statics solution within the limits.
  bool start_ramp(const Pose& goal) {
    planner_ = executor_;
    const auto r = planner_.set_target(goal);
    if (!r.within_limits) return false;
    executor_.set_target(goal);
    target_ = goal;
    return true;
  }

  /// Starts line i of a leg: a path, or a shape ramp (the executor's set_target).
  void start_leg(const Leg& leg, int i) {
    const auto k = static_cast<std::size_t>(i);
    if (!leg.ramp[k]) {
      start_path(leg.pose[k]);
      return;
    }
    if (!start_ramp(leg.pose[k])) give_up("a ramp target has no inverse statics solution within the actuation limits");
  }

  /// Whether object i is tall: its height above tall_ratio x its width.
  bool is_tall(int object) const {
    const auto& a = asset_of(object);
    return scene::asset_height(a) > config_.tall_ratio * 2 * std::max(a.bounding_half_extents.x(), a.bounding_half_extents.y());
  }
  /// Whether the held object is let go only once the arm is still (release_settle_speed): a
  /// tall one.
  bool release_settles() const { return config_.release_settle_speed > 0 && is_tall(plan_.object); }

  /// The end of the lower line: the place pose; for a tall object (release_settles()) lowered
  /// on by place_clearance + contact_depth, so that it reaches its support and is not dropped.
  /// Onto an item (SupportKind::onto: STK): no lower than where the fingertips are stack_finger_clearance above the item below's
  /// top (the closed fingers, at the held item's width, would land on its rim or inner wall
  /// before the held item nests); the item drops the rest of the way.
  Pose lower_goal() const {
    Pose p = plan_.place;
    if (release_settles() && config_.contact_depth > 0) p.translation.z() -= config_.place_clearance + config_.contact_depth;
    if (const Support below = support_of(move_); below.kind == SupportKind::onto) {
      const double lowest = top_of(below.object) + config_.stack_finger_clearance;
      p.translation.z() += std::max(0.0, lowest - fingertips(p).z());
    }
    return p;
  }

  /// Whether something under the held object carries it (see the lower phase).
  bool supported(const ObjectState& o) const {
    return o.touching != 0 || o.touches_table || o.pose.translation.z() < plan_.object_target.translation.z() - 0.5 * config_.place_clearance;
  }

  /// Whether the gripper touches anything but the held object: the closed fingers, at the held
  /// object's width, land on the rim or inner wall of a bowl below before the held bowl nests in
  /// it (the lower then opens there and the object drops the rest of the way).
  bool fingers_blocked(const TaskEnv::World& w) const {
    const rigid::BodyId g = w.gripper_body(), held = env_->bodies().objects[static_cast<std::size_t>(plan_.object)];
    for (const auto& m : w.rigid().manifolds()) {
      if (m.body_a != g && m.body_b != g) continue;
      if ((m.body_a == g ? m.body_b : m.body_a) != held && TaskEnv::touching(m)) return true;
    }
    return false;
  }

  /// Above the place pose by retract_height, or more until the fingertips are finger_clearance
  /// above the released object's top.
  Pose retract_pose() const {
    Pose up = plan_.place;
    up.translation.z() += std::max(config_.retract_height, top_of(plan_.object) + config_.finger_clearance - fingertips(plan_.place).z());
    return up;
  }

  /// Whether the open fingers clear the object by less than tight_clearance on each side (a
  /// plate, a bowl, a shoe): the arm then descends at tight_peak_speed, since its sideways sway
  /// on a fast descent lands a finger on the object's rim and tips it.
  bool tight_grasp() const {
    return 0.5 * (env_->gripper_parameters().open_width - plan_.width) < config_.tight_clearance;
  }

  /// How near the end of line leg_ of `leg` the arm must be for the next path to start:
  /// via_error at an arc or via point, start_error at the leg's last pose.
  double chain_error(const Leg& leg) const { return leg_ + 1 < leg.count ? config_.via_error : config_.start_error; }

  /// What the phase handlers read of the world after a control step.
  struct Tick {
    const TaskEnv::World& world;
    Pose ee;         ///< the end-effector frame
    double error;    ///< m: the end-effector from its target
    double speed;    ///< m/s: the arm's tip
    bool done;       ///< the executor's path is complete
    bool settled;    ///< done, slower than settle_speed and within settle_error
    bool holding;    ///< the gripper holds the moved object
  };

  Tick observe_tick(const TaskEnv::World& w) const {
    const auto f = w.soft().end_effector_frame();
    const double error = (f.position - target_.translation).norm();
    const auto& v = w.rod().state().velocities;
    const double speed = v.row(v.rows() - 1).norm();
    const bool done = executor_.path_done();
    const bool settled = done && speed < config_.settle_speed && error < config_.settle_error;
    const auto held = w.gripper().held();
    const bool holding = held && plan_.object >= 0 && *held == env_->bodies().objects[static_cast<std::size_t>(plan_.object)];
    return Tick{w, Pose{f.rotation, f.position}, error, speed, done, settled, holding};
  }

  /// The phase machine, after the last control step: one handler per phase.
  void advance(const TaskEnv::World& w) {
    const Tick t = observe_tick(w);
    switch (phase_) {
      case ExpertPhase::approach: advance_approach(t); break;
      case ExpertPhase::descend: advance_descend(t); break;
      case ExpertPhase::close: advance_close(t); break;
      case ExpertPhase::carry: advance_carry(t); break;
      case ExpertPhase::lower: advance_lower(t); break;
      case ExpertPhase::open: advance_open(t); break;
      case ExpertPhase::retract:
        if (t.done && t.error < config_.start_error) begin_move();
        break;
      case ExpertPhase::idle:
      case ExpertPhase::failed: break;
    }
  }

  /// Approach: the approach leg's lines in turn, then the descent to the grasp.
  void advance_approach(const Tick& t) {
    if (!(t.done && t.error < chain_error(plan_.approach_leg))) return;
    if (leg_ + 1 < plan_.approach_leg.count) {
      start_leg(plan_.approach_leg, ++leg_);
      return;
    }
    enter(ExpertPhase::descend);
    start_path(plan_.grasp, true, tight_grasp() ? config_.tight_peak_speed : 0.0);
  }

  /// Descend: at the grasp once settled, close.
  void advance_descend(const Tick& t) {
    if (!(t.done && (t.settled || ++waited_ > config_.max_settle_steps))) return;
    waited_ = 0;
    // blocked short of the grasp (a finger on the object): the hand would close around
    // the object askew, and its carry is then mostly beyond the actuation limits
    if (t.error > config_.grasp_error && retry_with_another_grasp()) return;
    s_ = 1;
    enter(ExpertPhase::close);
  }

  /// Close: once the object is held, the place corrected for where it sits in the hand and the
  /// carry checked from there; a missed grasp re-tries the move.
  void advance_close(const Tick& t) {
    if (!t.holding && t.world.gripper().closing()) return;  // the fingers are still on their way
    if (!t.holding) {
      s_ = 0;
      if (retries_++ < config_.max_retries) {
        begin_move();
      } else {
        give_up("missed grasp");
      }
      return;
    }
    const Pose object = state_of(plan_.object).pose;
    correct_place(t.ee, object);
    // neither carry passes from where the object sits in the hand: put it back (it still
    // stands where it was grasped) and re-try with another grasp
    if (!recheck_carry(t.ee, object) && retries_ < config_.max_retries) {
      executor_.set_payload(0.0);
      retry_with_another_grasp();
      return;
    }
    leg_ = 0;
    enter(ExpertPhase::carry);
    start_leg(plan_.carry_leg, 0);
  }

  /// Where the object sits in the hand (end-effector at `ee`, the object at `object`): the
  /// payload hint, the target orientation nearest the one this grasp releases it in, the place
  /// pose and the carry leg from there.
  void correct_place(const Pose& ee, const Pose& object) {
    const auto& a = asset_of(plan_.object);
    executor_.set_payload(a.mass, ee.rotation.transpose() * (object.act(a.center_of_mass) - ee.translation));
    {
      // the object's target orientation nearest the one this grasp would release it in
      const Eigen::Matrix3d would_be = (plan_.place * ee.inverse() * object).rotation;
      const auto symmetry = yaw_free(plan_.object) ? scene::Symmetry{scene::Symmetry::Kind::axial, 0} : scene::asset_symmetry(a);
      plan_.object_target.rotation = nearest_equivalent(would_be, plan_.object_target.rotation, symmetry);
    }
    plan_.place = plan_.object_target * object.inverse() * ee;
    set_carry_leg(plan_);
  }

  /// The corrected carry, checked (and repaired) from here; when it is refused, the other kind
  /// (direct or via the lift). True (plan_ takes the carry that passed) when one passes; false
  /// (plan_ keeps the planned kind as corrected) when both are refused.
  bool recheck_carry(const Pose& ee, const Pose& object) {
    for (const bool via : {plan_.via_carry, !plan_.via_carry}) {
      Plan checked = plan_;
      checked.via_carry = via;
      set_carry_leg(checked);
      repair_ = true;
      planner_ = executor_;
      planner_.complete_path();
      const char* why = "";
      if (check_carry_leg(checked, ee, object, support_of(move_).object, why) && check_line(checked.place, why)) {
        plan_ = checked;
        return true;
      }
    }
    return false;
  }

  /// Carry: the carry leg's lines in turn, then (once the arm's tip is slower than
  /// carry_settle_speed) the lower.
  void advance_carry(const Tick& t) {
    if (!t.holding) {
      give_up("dropped the object");
      return;
    }
    if (!(t.done && t.error < chain_error(plan_.carry_leg))) return;
    if (leg_ + 1 < plan_.carry_leg.count) {
      start_leg(plan_.carry_leg, ++leg_);
    } else if (!(config_.carry_settle_speed > 0) || t.speed < config_.carry_settle_speed || ++waited_ > config_.max_settle_steps) {
      waited_ = 0;
      enter(ExpertPhase::lower);
      // a long lower (into a container) runs at the carry's speed to slow_lower above its end first
      Pose fast = lower_goal();
      fast.translation.z() += config_.slow_lower;
      lower_fast_ = config_.slow_lower > 0 && target_.translation.z() - fast.translation.z() > config_.slow_lower;
      start_path(lower_fast_ ? fast : lower_goal(), true, lower_fast_ ? 0.0 : config_.lower_peak_speed);
    }
  }

  /// Lower: the fast line first (slow_lower), then the slow one; open once the object is
  /// supported (or the fingers blocked) or the lower settled.
  void advance_lower(const Tick& t) {
    if (!t.holding) {
      give_up("dropped the object");
      return;
    }
    if (lower_fast_ && !supported(state_of(plan_.object))) {
      if (t.done && t.error < config_.start_error) {
        lower_fast_ = false;
        // refused: the object is slow_lower above its release height already (into a
        // container: mostly below the rim), so it is let go from here once settled
        start_path(lower_goal(), false, config_.lower_peak_speed);
      }
      return;
    }
    lower_fast_ = false;
    // Its support already carries the object (it touches the table or another object, or
    // sank half the clearance below the release height): open now rather than press it in
    // until it slips.
    // With release_settle_speed, the arm stops where it is first and opens once its tip is
    // slower (a tall object let go while the arm still sways tips over).
    if (!touched_ && (supported(state_of(plan_.object)) || fingers_blocked(t.world))) {
      touched_ = true;
      waited_ = 0;
      if (release_settles()) {
        Pose hold = t.ee;  // where the arm is, lifted so it does not press on
        hold.translation.z() += config_.release_lift;
        start_path(hold, false);
      }
    }
    if (touched_ ? (!release_settles() || t.speed < config_.release_settle_speed || ++waited_ > config_.max_settle_steps)
                 : (t.done && (t.settled || ++waited_ > config_.max_settle_steps))) {
      touched_ = false;
      waited_ = 0;
      s_ = 0;
      executor_.set_payload(0.0);
      enter(ExpertPhase::open);
    }
  }

  /// Open: once the opening fingers clear a tall object (release_clearance), the retract; the
  /// next move starts from there.
  void advance_open(const Tick& t) {
    const auto& g = t.world.gripper();
    if (is_tall(plan_.object) && g.opening() && g.finger_width() < plan_.width + 2 * config_.release_clearance) return;
    // Up and away from the released object, also after the last move (fingers left
    // around it keep pushing it as the arm sways, and it never comes to rest).
    ++move_;
    retries_ = 0;
    excluded_.clear();
    enter(ExpertPhase::retract);
    // a refused retract is not a failure: the next move plans from here, or the arm holds
    if (!start_path(retract_pose(), false, config_.retract_peak_speed)) {
      if (move_ < moves_) begin_move();
      else enter(ExpertPhase::idle);
    }
  }

  const TaskEnv* env_;
  ExpertConfig config_;
  Executor executor_, planner_, planner_backup_;
  static constexpr int approach_raise_steps = 10;   ///< set_approach_leg: raises of a tall object's via point
  static constexpr double approach_raise_step = 0.01;  ///< m
  static constexpr int line_samples = 8;  ///< shapes checked along a planned line (arm_clear)
  double arm_margin_;                      ///< m: the rod's radius + arm_clearance (arm_clear)
  Array3 shape_;
  int plan_object_ = -1;
  control::Observation<double> observation_;
  Pose target_;
  Plan plan_;
  ExpertPhase phase_ = ExpertPhase::idle;
  int move_ = 0, moves_ = 0, retries_ = 0, s_ = 0, waited_ = 0, leg_ = 0;
  std::vector<Pose> excluded_;  ///< grasps (in the object's frame) re-tries of this move leave out
  long steps_ = 0;
  std::vector<ExpertEvent> events_;
  std::optional<std::string_view> failure_;
  std::string plan_refusal_;  ///< why the least-turning grasp candidate was refused
  bool repair_ = true;        ///< check_leg may repair refused lines
  bool touched_ = false;      ///< the lower phase found the object supported
  bool lower_fast_ = false;   ///< the lower phase's first, fast line (slow_lower)
  bool check_held_ = false;   ///< check_line also checks the held object (held_clear)
  Pose held_in_ee_;           ///< the held object's pose in the end-effector frame (held_clear)
  Vec3 gripper_center_, gripper_half_;    ///< the open gripper's box (palm and fingers) in the end-effector frame
  std::uint64_t held_near_ = 0;  ///< objects the held one or the gripper starts or ends near (held_clear)
};

}  // namespace manisoft::task
