// The expert's checks of a planned line (paper section 3.4): a line is accepted when the model
// executor accepts its whole sequence (continuous shapes within the actuation limits, the payload
// included; ModelExecutor::track_line, timed by line_steps()), its end shape keeps every rod node
// checks.table_clearance above the table top, and along it (line_samples shapes) the rod keeps
// checks.arm_clearance from the bounding box of every obstacle and every object but the moved one
// (arm_clear()). Along a carry the held object's and the open gripper's boxes also keep
// checks.held_clearance from the other objects' and obstacles' boxes, except those they cannot
// avoid at the grasp or the place (held_clear(); oriented boxes: geometry/box_overlap.hpp). What a
// check is about is passed explicitly (LinePlan: the moved object, whether refused lines may be
// repaired, the held object's place in the hand). A refused line may be repaired (LinePlan::repair:
// check_leg()) by the executor's shape ramp to the pose's cold inverse statics solution
// (ModelExecutor::set_target; paths.ramp_fallback), when that is within the limits and clear of the
// table (the ramp's intermediate shapes are not checked). The checks run on a copy of the executor
// (planner_), chained line after line.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>

#include "manisoft/geometry/box_overlap.hpp"
#include "manisoft/task/expert_legs.hpp"

namespace manisoft::task::detail {

/// What the line checks of one plan are about: the object being moved (not an obstacle to its
/// own grasp and carry), whether a refused line may be repaired by a shape ramp, and, along a
/// carry, where the held object sits in the hand and which objects it may stay near.
struct LinePlan {
  LinePlan(int moved, bool may_repair) : object(moved), repair(may_repair) {}

  int object = -1;            ///< the moved object (-1: none)
  bool repair = false;        ///< check_leg may repair refused lines by shape ramps (paths.ramp_fallback)
  bool holding = false;       ///< the lines are timed as loaded and the held object is checked (held_clear)
  math::Pose<double> held_in_ee;  ///< the held object's pose in the end-effector frame (holding)
  std::uint64_t held_near = 0;  ///< objects the held one or the gripper starts or ends near: not held against it (holding)
};

/// Control steps of a straight line `distance` long, timed by ModelExecutor::track_line's profile
/// (paths.cruise) at peak end-effector speed `peak` (m/s) and, when `max_accel` > 0, peak
/// acceleration at most `max_accel` (m/s^2); at least paths.min_segment_steps.
inline int timed_line_steps(const ExpertConfig::Paths& paths, double control_dt, double distance, double peak, double max_accel) {
  using Executor = TaskEnv::Executor;
  double seconds = Executor::peak_speed_ratio(paths.cruise) * distance / peak;
  // the timing's peak acceleration is shape x distance / T^2
  if (max_accel > 0) seconds = std::max(seconds, std::sqrt(Executor::peak_acceleration_ratio(paths.cruise) * distance / max_accel));
  return std::max(paths.min_segment_steps, static_cast<int>(std::ceil(seconds / control_dt)));
}

/// The expert's line checks on its planning copy of the executor (a base of Expert).
class ExpertChecks : protected ExpertLegs {
 protected:
  ExpertChecks(const TaskEnv& env, const ExpertConfig& config)
      : ExpertLegs(env, config), planner_(env.home_executor()), planner_backup_(env.home_executor()),
        arm_margin_(std::sqrt(env.arm_model().rod.cross_section_area.maxCoeff() / std::numbers::pi) + config.checks.arm_clearance) {}

  /// Control steps of a line `distance` long at its peak end-effector speed (`peak_speed`, or
  /// the configured one with the gripper empty or holding), before the node speed bound; holding
  /// object `held`, also within carry.grip_share of what the grip holds.
  int line_steps(double distance, bool loaded, double peak_speed, int held) const {
    const double peak = peak_speed > 0 ? peak_speed : loaded ? config_.carry.peak_speed : config_.paths.peak_speed;
    double max_accel = 0;
    if (loaded && config_.carry.grip_share > 0 && held >= 0)
      max_accel = config_.carry.grip_share * env_->gripper_parameters().max_hold_force / asset_of(held).mass;
    return timed_line_steps(config_.paths, env_->control_dt(), distance, peak, max_accel);
  }
  /// The node speed bound of a line, m per control step.
  double node_step(bool loaded) const { return (loaded ? config_.carry.node_speed : config_.paths.node_speed) * env_->control_dt(); }
  /// Tracks one line to `to` on planner_ (from its shape target) and jumps to its end; false
  /// (the planner as before, `why` set) when the executor refuses it or its end shape comes
  /// within checks.table_clearance of the table top.
  bool check_line(const Pose& to, const LinePlan& plan, const char*& why) {
    planner_backup_ = planner_;
    const Pose from = planner_.statics().desired_tip_pose();
    const int steps = line_steps((to.translation - from.translation).norm(), plan.holding, 0, plan.object);
    const auto report = planner_.track_line(to, steps, node_step(plan.holding), config_.paths.cruise);
    bool clear = report.accepted && held_line_clear(from, to, plan);
    for (int k = 1; k <= line_samples && report.accepted && clear; ++k) {
      planner_.predicted_shape(long(report.steps) * k / line_samples, shape_);
      clear = arm_clear(shape_, plan.object);
    }
    planner_.complete_path();
    if (!report.accepted || !clear) {
      why = report.accepted ? "the arm would hit an object or obstacle" : report.reason;
      planner_ = planner_backup_;
      return false;
    }
    if (planner_.statics().desired_state().positions.col(2).minCoeff() < env_->spec().table.top_center.z() + config_.checks.table_clearance) {
      why = "the arm would touch the table";
      planner_ = planner_backup_;
      return false;
    }
    return true;
  }
  /// Whether a shape of the arm (every rod node but the tip, which sits in the palm) keeps the
  /// rod's surface checks.arm_clearance clear of the bounding box of every object but `moved` (as
  /// they stand now) and of every obstacle: a node hits a box when, in the box's frame, it is
  /// within the half extents plus the rod radius and clearance on every axis.
  bool arm_clear(const Array3& positions, int moved) const {
    if (!config_.checks.objects) return true;
    const auto& s = env_->spec();
    auto hits = [&](const Pose& pose, const assets::Asset& a) {
      for (Eigen::Index j = 0; j + 1 < positions.rows(); ++j) {
        const Vec3 q = pose.inverse_act(Vec3(positions.row(j).transpose())) - a.bounding_center;
        if ((q.cwiseAbs() - a.bounding_half_extents).maxCoeff() < arm_margin_) return true;
      }
      return false;
    };
    for (std::size_t i = 0; i < s.objects.size(); ++i)
      if (static_cast<int>(i) != moved && hits(state_of(static_cast<int>(i)).pose, asset_of(static_cast<int>(i)))) return false;
    for (const auto& o : s.obstacles)
      if (hits(o.pose, env_->library().get(o.asset_id, "expert obstacle"))) return false;
    return true;
  }
  /// Whether the held object (plan.holding: along a carry leg), carried at plan.held_in_ee by the
  /// end-effector at fraction u of the straight line from -> to, and the open gripper's box keep
  /// checks.held_clearance clear of the bounding box of every obstacle and every other object but
  /// those they are that near where the carry starts or the object is placed (plan.held_near:
  /// unavoidable; its support excepted). Oriented boxes, separating axes.
  bool held_clear(const Pose& from, const Pose& to, double u, const LinePlan& plan) const {
    if (!plan.holding || !config_.checks.objects) return true;
    Pose ee;
    ee.translation = from.translation + u * (to.translation - from.translation);
    ee.rotation = Eigen::Quaterniond(from.rotation).slerp(u, Eigen::Quaterniond(to.rotation)).toRotationMatrix();
    const auto& s = env_->spec();
    for (std::size_t i = 0; i < s.objects.size(); ++i) {
      const int o = static_cast<int>(i);
      if (o != plan.object && !(plan.held_near >> i & 1u) && held_near(ee, state_of(o).pose, asset_of(o), plan)) return false;
    }
    for (const auto& o : s.obstacles)
      if (held_near(ee, o.pose, env_->library().get(o.asset_id, "expert obstacle"), plan)) return false;
    return true;
  }
  /// held_clear() at line_samples points of the straight line from -> to.
  bool held_line_clear(const Pose& from, const Pose& to, const LinePlan& plan) const {
    for (int k = 1; k <= line_samples; ++k)
      if (!held_clear(from, to, double(k) / line_samples, plan)) return false;
    return true;
  }
  /// Whether the held object's box (plan.held_in_ee) or the open gripper's box, the end-effector
  /// at `ee`, comes within checks.held_clearance of the bounding box of `asset` at `pose`.
  bool held_near(const Pose& ee, const Pose& pose, const assets::Asset& asset, const LinePlan& plan) const {
    return boxes_overlap(ee * plan.held_in_ee, asset_of(plan.object), pose, asset, config_.checks.held_clearance) ||
           geometry::boxes_overlap(ee, gripper_center_, gripper_half_, pose, asset.bounding_center, asset.bounding_half_extents, config_.checks.held_clearance);
  }
  /// Checks plan p's carry leg on planner_ (check_leg) with the held object too (held_clear):
  /// the object at `object` when the end-effector is at `ee`, where the carry starts; what it is
  /// near there and at the place pose (but `support`) is not held against it. `plan`: the moved
  /// object and whether refused lines may be repaired.
  bool check_carry_leg(Plan& p, const Pose& ee, const Pose& object, int support, const LinePlan& plan, const char*& why) {
    LinePlan carried = plan;
    carried.holding = true;
    carried.held_in_ee = ee.inverse() * object;
    carried.held_near = objects_held_near(ee, carried) | objects_held_near(p.place, carried, support);
    return check_leg(p.carry_leg, carried, why);
  }
  /// The objects (bits by index) the held object's or the gripper's box is within
  /// checks.held_clearance of with the end-effector at `ee` (where the carry starts, where the
  /// object is placed: unavoidable), but the moved one and `except`.
  std::uint64_t objects_held_near(const Pose& ee, const LinePlan& plan, int except = -1) const {
    const auto& s = env_->spec();
    std::uint64_t near = 0;
    for (std::size_t i = 0; i < s.objects.size() && i < 64; ++i) {
      const int o = static_cast<int>(i);
      if (o != plan.object && o != except && held_near(ee, state_of(o).pose, asset_of(o), plan)) near |= std::uint64_t(1) << i;
    }
    return near;
  }
  /// Whether the bounding boxes of assets a (at pose pa) and b (at pb) come within `margin` of
  /// each other: no separating axis among the 15 of two oriented boxes.
  static bool boxes_overlap(const Pose& pa, const assets::Asset& a, const Pose& pb, const assets::Asset& b, double margin) {
    return geometry::boxes_overlap(pa, a.bounding_center, a.bounding_half_extents, pb, b.bounding_center, b.bounding_half_extents, margin);
  }
  /// Checks a ramp to `to` on planner_ (the cold inverse statics solution within the limits and
  /// clear of the table) and jumps to its end; false (the planner as before) otherwise.
  bool check_ramp(const Pose& to, const LinePlan& plan) {
    // a held object is checked along the straight line (a ramp's own course is not known before it
    // runs)
    if (!held_line_clear(planner_.statics().desired_tip_pose(), to, plan)) return false;
    planner_backup_ = planner_;
    const auto r = planner_.set_target(to);
    planner_.complete_path();
    const auto& end = planner_.statics().desired_state().positions;
    if (r.within_limits && end.col(2).minCoeff() >= env_->spec().table.top_center.z() + config_.checks.table_clearance && arm_clear(end, plan.object)) return true;
    planner_ = planner_backup_;
    return false;
  }
  /// Checks a leg's lines on planner_; when plan.repair, a refused line becomes a shape ramp when
  /// check_ramp() accepts it. False when a line is refused.
  bool check_leg(Leg& leg, const LinePlan& plan, const char*& why) {
    for (int i = 0; i < leg.count; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (leg.ramp[k] ? check_ramp(leg.pose[k], plan) : check_line(leg.pose[k], plan, why)) continue;
      if (!plan.repair || !config_.paths.ramp_fallback || !check_ramp(leg.pose[k], plan)) return false;
      leg.ramp[k] = true;
    }
    return true;
  }

  Executor planner_, planner_backup_;
  static constexpr int line_samples = 8;  ///< shapes checked along a planned line (arm_clear)
  double arm_margin_;                      ///< m: the rod's radius + checks.arm_clearance (arm_clear)
  Array3 shape_;
};

}  // namespace manisoft::task::detail
