// What every task's success predicate reads and shares (the ManiSoft benchmark paper, "ManiSoft:
// a vision-language benchmark for soft robotic manipulation", sections 3.2 and 3.4): one control
// step's snapshot of the objects (`Snapshot`: poses, velocities, who touches whom, whether the
// gripper is open and holds something), the tolerances of every predicate, the failure reasons,
// "released" and "at rest" (ManiSkill's static test) and `SuccessTracker`, which turns a per-step
// predicate into an episode's outcome. The predicates themselves are the tasks' own (coll.hpp,
// aln.hpp, stk.hpp, arr.hpp, ovr.hpp; the list in registry.hpp); the paper defines no success criterion,
// so they follow the best rigid-arm benchmarks (RoboTwin 2.0's placement and stacking checks,
// LIBERO's On/In predicates, ManiSkill's "static" test), documented in docs/tasks.md.
//
// Every predicate is a pure function of a snapshot, so it can be checked on hand-built states
// and on recorded episodes alike. Spatial words are the viewer's (geometry/spatial_relation.hpp):
// "left" is world -y, "in front of" +x.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <string_view>

#include "manisoft/assets/asset.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/geometry/spatial_relation.hpp"
#include "manisoft/math/se3.hpp"
#include "manisoft/scene/scene_spec.hpp"

namespace manisoft::task {

/// Why an episode failed (machine-readable, as datasets and evaluation tables report it).
enum class FailureReason { none, timeout, object_dropped, object_off_table, arm_hit_obstacle, diverged, scene_invalid };

inline std::string_view to_string(FailureReason reason) {
  switch (reason) {
    case FailureReason::none: return "none";
    case FailureReason::timeout: return "timeout";
    case FailureReason::object_dropped: return "object_dropped";
    case FailureReason::object_off_table: return "object_off_table";
    case FailureReason::arm_hit_obstacle: return "arm_hit_obstacle";
    case FailureReason::diverged: return "diverged";
    case FailureReason::scene_invalid: return "scene_invalid";
  }
  return "?";
}

/// The largest number of objects a snapshot describes (contacts are a bit mask).
inline constexpr int max_objects = 64;

/// One object (manipulable or obstacle) at one control step.
struct ObjectState {
  math::Pose<double> pose;                                      ///< asset frame -> world
  Eigen::Vector3d center_of_mass{Eigen::Vector3d::Zero()};      ///< world, m
  Eigen::Vector3d linear_velocity{Eigen::Vector3d::Zero()};     ///< of the centre of mass, m/s
  Eigen::Vector3d angular_velocity{Eigen::Vector3d::Zero()};    ///< world, rad/s
  bool touches_table = false;
  std::uint64_t touching = 0;  ///< bit j set: in contact with object j
  bool held = false;           ///< grasped by the gripper

  bool touches(int other) const { return (touching >> other) & 1u; }
};

/// What the predicates read at one control step. Objects are indexed as in the scene.
struct Snapshot {
  std::span<const ObjectState> objects;
  bool gripper_open = true;
};

/// Tolerances of every predicate (SI units). The defaults are the benchmark's definition.
struct Tolerances {
  // "At rest" (ManiSkill's static test): speeds below these.
  double rest_linear_speed = 0.01;    ///< m/s
  double rest_angular_speed = 0.1;    ///< rad/s
  // COLL: how far above the container's rim the object's centre of mass may be and still count
  // as inside (0: strictly inside the inner volume).
  double coll_above_rim = 0.0;        ///< m
  // ALN: distance of the asset origins and angle between the orientations (modulo symmetry).
  double aln_position = 0.02;         ///< m
  double aln_orientation = 0.2;       ///< rad
  // OVR: the object's z axis from world z (it is judged upright at any yaw: the marker shows
  // where, the obstacle is the task); ALN's orientation tolerance, which an object standing on
  // its base meets unless it leans on something or lies down.
  double ovr_upright = 0.2;           ///< rad
  // STK: horizontal offset of each item's centre of mass from the one below.
  double stk_horizontal = 0.03;       ///< m
  // ARR: the relations' margins (geometry/spatial_relation.hpp).
  geometry::RelationTolerances arr;
};

/// True when the object is slower than the rest thresholds and not held.
inline bool at_rest(const ObjectState& object, const Tolerances& tol = {}) {
  return !object.held && object.linear_velocity.norm() < tol.rest_linear_speed &&
         object.angular_velocity.norm() < tol.rest_angular_speed;
}

namespace detail {

inline const ObjectState& object_at(const Snapshot& snapshot, int index) {
  if (index < 0 || index >= static_cast<int>(snapshot.objects.size()) || index >= max_objects) {
    ::manisoft::detail::fail("object index ", index, " is out of range: the snapshot has ", snapshot.objects.size(), " objects");
  }
  return snapshot.objects[static_cast<std::size_t>(index)];
}

}  // namespace detail

/// Released: the gripper open and holding none of these objects.
inline bool released(const Snapshot& snapshot, std::span<const int> indices) {
  if (!snapshot.gripper_open) return false;
  for (int i : indices)
    if (detail::object_at(snapshot, i).held) return false;
  return true;
}

/// At rest: all of these objects slower than the rest thresholds.
inline bool all_at_rest(const Snapshot& snapshot, std::span<const int> indices, const Tolerances& tol) {
  for (int i : indices) {
    const ObjectState& o = detail::object_at(snapshot, i);
    if (!(o.linear_velocity.norm() < tol.rest_linear_speed && o.angular_velocity.norm() < tol.rest_angular_speed)) return false;
  }
  return true;
}

/// How an object's orientation goal is judged (defined with the scene's goal).
using Symmetry = scene::Symmetry;

/// Angle (rad) between two orientations, modulo the symmetry about the asset's z axis.
inline double orientation_error(const Eigen::Matrix3d& actual, const Eigen::Matrix3d& goal, const Symmetry& symmetry) {
  const auto angle_of = [](const Eigen::Matrix3d& r) {
    return std::acos(std::clamp((r.trace() - 1.0) / 2.0, -1.0, 1.0));
  };
  switch (symmetry.kind) {
    case Symmetry::Kind::none: return angle_of(goal.transpose() * actual);
    case Symmetry::Kind::axial: {
      // Only where the symmetry axis points matters.
      return std::acos(std::clamp(actual.col(2).dot(goal.col(2)), -1.0, 1.0));
    }
    case Symmetry::Kind::discrete: {
      if (symmetry.order < 1) ::manisoft::detail::fail("Symmetry::order = ", symmetry.order, " must be >= 1");
      double best = 4.0;
      for (int k = 0; k < symmetry.order; ++k) {
        const double yaw = 2.0 * 3.14159265358979323846 * k / symmetry.order;
        const Eigen::Matrix3d turned = actual * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
        best = std::min(best, angle_of(goal.transpose() * turned));
      }
      return best;
    }
  }
  return 4.0;
}

/// Turns a per-step predicate into an episode's outcome: success once the predicate has held for
/// `hold_steps` consecutive control steps (reported at the first step where that is reached), and
/// whether it still holds at the end (ManiSkill reports both).
class SuccessTracker {
 public:
  explicit SuccessTracker(int hold_steps = 1) : hold_steps_(hold_steps) {
    if (hold_steps < 1) ::manisoft::detail::fail("SuccessTracker: hold_steps = ", hold_steps, " must be >= 1");
  }

  /// Records control step `step`'s predicate value; true at the step where success is reached.
  bool update(long step, bool holds) {
    run_ = holds ? run_ + 1 : 0;
    holds_now_ = holds;
    if (first_success_step_ < 0 && run_ >= hold_steps_) {
      first_success_step_ = step;
      return true;
    }
    return false;
  }

  bool succeeded() const { return first_success_step_ >= 0; }
  long first_success_step() const { return first_success_step_; }  ///< -1 while not succeeded
  bool holds_now() const { return holds_now_; }                    ///< "success at end" once the episode ends

 private:
  int hold_steps_;
  int run_ = 0;
  bool holds_now_ = false;
  long first_success_step_ = -1;
};

}  // namespace manisoft::task
