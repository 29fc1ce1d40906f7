// The expert's waypoint geometry (paper section 3.4): where the end effector goes for one move
// "put object i at pose P" (the task type's move(): moves.hpp), as legs of straight lines.
//
// A move's waypoints (end-effector frame): approach (along the grasp annotation's approach
// direction, approach.distance from the grasp), grasp, carry (above the place pose, diagonal from
// the grasp), place. Each leg is direct or "via": the approach first level to above the approach
// pose, for a tall object high enough that the fingertips pass approach.tip_clearance above its
// top, and higher while the line there would still sweep them into it (approach_clear()); the carry
// first straight up by carry.lift_height, or until the object's bottom is 2 x checks.held_clearance
// above every other object and obstacle near its course (corridor_top()). The high variants raise
// their via points by approach.via_raise. A leg whose straight line would pass towards the inner
// edge of the arm's reach (paths.arc_inset nearer its base than its farther end) goes round an arc
// point about the base instead (append_leg()). Into a container (SupportKind::into) the object is
// lowered below the rim as far as the fingers allow (sink_into_container()).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>

#include "manisoft/scene/asset_library.hpp"
#include "manisoft/task/expert_config.hpp"
#include "manisoft/task/moves.hpp"
#include "manisoft/task/registry.hpp"
#include "manisoft/task/task_env.hpp"

namespace manisoft::task::detail {

/// The expert's scene reading and leg geometry (the base of Expert: expert.hpp).
class ExpertLegs {
 public:
  using Pose = math::Pose<double>;
  using Vec3 = Eigen::Vector3d;
  using Array3 = TaskEnv::Array3;
  using Executor = TaskEnv::Executor;

 protected:
  ExpertLegs(const TaskEnv& env, const ExpertConfig& config) : env_(&env), config_(config) {
    config_.validate();
    const auto& gp = env.gripper_parameters();
    gripper_half_ = Vec3(std::max(gp.palm_half_x, 0.5 * gp.open_width + gp.finger_thickness), std::max(gp.palm_half_y, gp.finger_half_width),
                         0.5 * (gp.palm_thickness + gp.finger_length));
    gripper_center_ = Vec3(0, 0, gripper_half_.z());
  }

  /// One move: the object, where it goes, and the end-effector waypoints. A leg is one or two
  /// straight lines: direct, or "via" (approach: level to above the approach pose first; carry:
  /// straight up by carry.lift_height first, then level to above the place pose).
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
  const assets::Asset& asset_of(int object) const {
    return env_->library().get(env_->spec().objects.at(static_cast<std::size_t>(object)).asset_id, "expert object");
  }
  const ObjectState& state_of(int object) const { return env_->snapshot().objects[static_cast<std::size_t>(object)]; }
  /// Where the fingertips are (world) at end-effector pose `p`.
  Vec3 fingertips(const Pose& p) const {
    const auto& gp = env_->gripper_parameters();
    return p.act(Vec3(0, 0, gp.palm_thickness + gp.finger_length));
  }
  /// Height (world z) of object i's top as it stands now.
  double top_of(int object) const { return state_of(object).pose.act(Vec3(0, 0, scene::asset_height(asset_of(object)))).z(); }
  /// Whether object i is tall: its height above release.tall_ratio x its width.
  bool is_tall(int object) const {
    const auto& a = asset_of(object);
    return scene::asset_height(a) > config_.release.tall_ratio * 2 * std::max(a.bounding_half_extents.x(), a.bounding_half_extents.y());
  }
  /// Whether the yaw of the object's target pose is free: the object is round, or the task
  /// states no orientation (states_yaw).
  bool yaw_free(int object) const {
    const bool states_yaw = visit_task(env_->spec().task, []<TaskType T>(T) { return T::states_yaw; });
    return !states_yaw || scene::asset_symmetry(asset_of(object)).kind == scene::Symmetry::Kind::axial;
  }

  /// Angle between an end-effector orientation and the home one.
  double turn_from_home(const Pose& p) const { return Eigen::AngleAxisd(p.rotation * env_->home_pose().rotation.transpose()).angle(); }
  int count_moves() const {
    const auto& s = env_->spec();
    return visit_task(s.task, [&s]<TaskType T>(T) { return T::moves(s); });
  }
  /// Move k: which object goes where (read from the current state; the task type's move()).
  Move move_goal(int k) const {
    const Snapshot snapshot = env_->snapshot();
    const MoveScene scene{env_->spec(), env_->library(), snapshot, config_.lower.place_clearance};
    return visit_task(env_->spec().task, [&]<TaskType T>(T) { return T::move(k, scene); });
  }
  /// What move k puts its object into or onto (COLL: the container, STK: the item below; -1: the
  /// table): the carry keeps clear of it until it lowers the object.
  Support support_of(int k) const {
    const auto& s = env_->spec();
    return visit_task(s.task, [&]<TaskType T>(T) { return T::support(k, s); });
  }
  /// Appends `to` to a leg, after an arc point when the straight line from `from` would pass
  /// paths.arc_inset closer to the arm's base (horizontally) than its farther end: the arm reaches
  /// an annulus about its base, and a chord cuts towards its inner edge. The arc point: the farther
  /// end's distance from the base at the ends' mean bearing, the higher end's height, the
  /// orientations' midway.
  void append_leg(Leg& leg, const Pose& from, const Pose& to) const {
    const Eigen::Vector2d base = env_->spec().arm_mount.base_position.head<2>();
    const Eigen::Vector2d a = from.translation.head<2>() - base, b = to.translation.head<2>() - base, ab = b - a;
    const double t = ab.squaredNorm() > 1e-12 ? std::clamp(-a.dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    if ((a + t * ab).norm() < std::max(a.norm(), b.norm()) - config_.paths.arc_inset) {
      const double r = std::max(a.norm(), b.norm());
      const double bearing = std::atan2(a.y(), a.x()) + 0.5 * std::remainder(std::atan2(b.y(), b.x()) - std::atan2(a.y(), a.x()), 2 * std::numbers::pi);
      Pose via;
      via.translation << base + r * Eigen::Vector2d(std::cos(bearing), std::sin(bearing)), std::max(from.translation.z(), to.translation.z());
      via.rotation = Eigen::Quaterniond(from.rotation).slerp(0.5, Eigen::Quaterniond(to.rotation)).toRotationMatrix();
      leg.push(via);
    }
    leg.push(to);
  }
  /// The annotation's approach pose moved to approach.distance from its grasp (same direction).
  Pose approach_pose(const assets::GraspAnnotation& g) const {
    Pose a = g.approach;
    const Vec3 d = g.approach.translation - g.grasp.translation;
    if (d.norm() > 1e-9) a.translation = g.grasp.translation + config_.approach.distance * d.normalized();
    return a;
  }
  /// The approach leg from the end-effector pose `from` (the annotation's approach pose last).
  /// "via": to above the approach pose first, then straight down; for a tall object (is_tall())
  /// high enough that the fingertips pass approach.tip_clearance above its top, and raised by
  /// another approach_raise_step (up to approach_raise_steps times) while the line there would
  /// still bring the open fingers into its reach (approach_clear(): a line that climbs from a
  /// lower start enters that reach before it is high enough). Returns approach_clear() of the leg.
  bool set_approach_leg(Plan& p, const Pose& approach, const Pose& from) const {
    p.start = from;
    Pose above = approach;
    above.translation.z() = std::max(approach.translation.z(), from.translation.z()) + p.raise;
    const bool tall = p.via_approach && is_tall(p.object);
    if (tall)
      above.translation.z() = std::max(above.translation.z(), approach.translation.z() + top_of(p.object) + config_.approach.tip_clearance - fingertips(approach).z());
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
  /// wherever the fingertips are lower than approach.tip_clearance above its top, the gripper's
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
        if (tips.z() < top + config_.approach.tip_clearance && d > between && d < reach && (tips.head<2>() - last).norm() > straddle) return false;
      }
      prev = to;
    }
    return true;
  }
  /// Into a container (SupportKind::into: COLL): the object is released low in the container (its
  /// bottom lower.place_clearance above the floor) rather than dropped from above the rim (a tall
  /// one dropped inner_depth rocks on in the container for seconds), as far as the fingertips stay
  /// retract.finger_clearance above the rim, or down to the floor when the open gripper fits into
  /// the opening (a basket). move_goal() puts the object's bottom lower.place_clearance above the
  /// rim; this lowers it.
  void sink_into_container(Plan& p, const Support& support) const {
    if (support.kind != SupportKind::into) return;
    const auto& rc = asset_of(support.object).receptacles.at(0);
    // A container whose opening the open gripper fits into (retract.finger_clearance to spare, at
    // any yaw): the object goes down to its floor.
    const double reach = std::hypot(gripper_half_.x(), gripper_half_.y());
    const double room = rc.inner_radius > 0 ? rc.inner_radius : rc.inner_half_extents.minCoeff();
    const double rim = (state_of(support.object).pose * rc.opening).translation.z();
    p.sink = room >= reach + config_.retract.finger_clearance ? rc.inner_depth
                                                                : std::clamp(fingertips(p.place).z() - (rim + config_.retract.finger_clearance), 0.0, rc.inner_depth);
    p.place.translation.z() -= p.sink;
    p.object_target.translation.z() -= p.sink;
  }
  /// The carry leg from the grasp to carry.height (plus the sink) above the place pose.
  void set_carry_leg(Plan& p) const {
    Pose above = p.place;
    above.translation.z() += config_.carry.height + p.sink;
    p.carry_leg.clear();
    Pose prev = p.grasp;
    if (p.via_carry) {
      Pose lift = p.grasp;
      lift.translation.z() += std::max(config_.carry.lift_height, corridor_top(p) + 2 * config_.checks.held_clearance - state_of(p.object).pose.translation.z()) + p.raise;
      above.translation.z() = std::max(above.translation.z(), lift.translation.z());
      append_leg(p.carry_leg, prev, lift);
      prev = lift;
    }
    append_leg(p.carry_leg, prev, above);
  }
  /// The highest top (world z) of the other objects and obstacles near the carry's course from
  /// the grasp to the place (the straight line or, at the edge of the reach, its arc point:
  /// append_leg), horizontally within their footprint radius plus the moved object's plus
  /// checks.held_clearance; the table top when there are none.
  double corridor_top(const Plan& p) const {
    Leg course;
    append_leg(course, p.grasp, p.place);
    const double r = scene::footprint_radius(asset_of(p.object)) + config_.checks.held_clearance;
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

  const TaskEnv* env_;
  ExpertConfig config_;
  static constexpr int approach_raise_steps = 10;   ///< set_approach_leg: raises of a tall object's via point
  static constexpr double approach_raise_step = 0.01;  ///< m
  Vec3 gripper_center_, gripper_half_;    ///< the open gripper's box (palm and fingers) in the end-effector frame
};

}  // namespace manisoft::task::detail
