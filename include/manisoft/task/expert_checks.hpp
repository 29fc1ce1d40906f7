// The expert's checks of a planned line (paper section 3.4): a line is accepted when the model
// executor accepts its whole sequence (continuous shapes within the actuation limits, the
// payload included; ModelExecutor::track_line, timed by line_steps()), its end shape keeps every
// rod node table_clearance above the table top, and along it (line_samples shapes) the rod keeps
// arm_clearance from the bounding box of every obstacle and every object but the moved one
// (arm_clear()). Along a carry the held object's and the open gripper's boxes also keep
// held_clearance from the other objects' and obstacles' boxes, except those they cannot avoid at
// the grasp or the place (held_clear(); oriented boxes: geometry/box_overlap.hpp).
// A refused line may be repaired (repair_: check_leg()) by the executor's shape ramp to the
// pose's cold inverse statics solution (ModelExecutor::set_target; ramp_fallback), when that is
// within the limits and clear of the table (the ramp's intermediate shapes are not checked).
// The checks run on a copy of the executor (planner_), chained line after line.
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

/// The expert's line checks on its planning copy of the executor (a base of Expert).
class ExpertChecks : protected ExpertLegs {
 protected:
  ExpertChecks(const TaskEnv& env, const ExpertConfig& config)
      : ExpertLegs(env, config), planner_(env.home_executor()), planner_backup_(env.home_executor()),
        arm_margin_(std::sqrt(env.arm_model().rod.cross_section_area.maxCoeff() / std::numbers::pi) + config.arm_clearance) {}

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

  Executor planner_, planner_backup_;
  static constexpr int line_samples = 8;  ///< shapes checked along a planned line (arm_clear)
  double arm_margin_;                      ///< m: the rod's radius + arm_clearance (arm_clear)
  Array3 shape_;
  int plan_object_ = -1;
  bool repair_ = true;        ///< check_leg may repair refused lines
  bool check_held_ = false;   ///< check_line also checks the held object (held_clear)
  Pose held_in_ee_;           ///< the held object's pose in the end-effector frame (held_clear)
  std::uint64_t held_near_ = 0;  ///< objects the held one or the gripper starts or ends near (held_clear)
};

}  // namespace manisoft::task::detail
