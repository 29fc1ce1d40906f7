// Success predicates of the four ManiSoft tasks (the ManiSoft benchmark paper, "ManiSoft: a
// vision-language benchmark for soft robotic manipulation", sections 3.2 and 3.4: COLL, ALN, STK,
// ARR). The paper defines no success criterion; these follow the best rigid-arm benchmarks
// (RoboTwin 2.0's placement and stacking checks, LIBERO's On/In predicates, ManiSkill's "static"
// test) with the tolerances in `Tolerances`, all documented in the README ("Tasks").
//
// Every predicate is a pure function of one control step's snapshot (`Snapshot`: object poses,
// velocities, who touches whom, whether the gripper is open and holds something), so it can be
// checked on hand-built states and on recorded episodes alike. Holding a predicate for a while
// ("at rest for 1 s") is `SuccessTracker`'s job.
//
// Spatial words are the viewer's (geometry/spatial_relation.hpp): "left" is world -y, "in front of" +x.
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

/// Released and at rest: the gripper open, holding nothing of these, all slower than the limits.
inline bool released_at_rest(const Snapshot& snapshot, std::span<const int> indices, const Tolerances& tol) {
  if (!snapshot.gripper_open) return false;
  for (int i : indices) {
    if (!at_rest(object_at(snapshot, i), tol)) return false;
  }
  return true;
}

}  // namespace detail

/// COLL: the object's centre of mass inside the container's inner volume (the receptacle, in
/// the container's asset frame), the object touching the container and not the table, both
/// released and at rest.
inline bool collected(const Snapshot& snapshot, int object, int container, const assets::Receptacle& receptacle,
                      const Tolerances& tol = {}) {
  const ObjectState& o = detail::object_at(snapshot, object);
  const ObjectState& c = detail::object_at(snapshot, container);
  const std::array<int, 2> both{object, container};
  if (!detail::released_at_rest(snapshot, both, tol)) return false;
  if (!o.touches(container) || o.touches_table) return false;
  // Centre of mass in the opening frame: z up out of the opening, floor at -inner_depth.
  const Eigen::Vector3d p = receptacle.opening.inverse_act(c.pose.inverse_act(o.center_of_mass));
  if (p.z() < -receptacle.inner_depth || p.z() > tol.coll_above_rim) return false;
  if (receptacle.inner_radius > 0) return p.head<2>().norm() <= receptacle.inner_radius;
  return std::abs(p.x()) <= receptacle.inner_half_extents.x() && std::abs(p.y()) <= receptacle.inner_half_extents.y();
}

/// How an object's orientation goal is judged: fully, up to a rotation about the asset's z axis
/// (a bottle, a can), or up to a 1/n turn about it (a box: n = 2 or 4).
struct Symmetry {
  enum class Kind { none, axial, discrete } kind = Kind::none;
  int order = 1;  ///< discrete: n-fold about z

  static Symmetry none() { return {}; }
  static Symmetry axial() { return {Kind::axial, 1}; }
  static Symmetry discrete(int n) { return {Kind::discrete, n}; }
};

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

/// ALN: the object's asset origin within `aln_position` of the goal's, its orientation within
/// `aln_orientation` of the goal's modulo `symmetry`, released and at rest.
inline bool aligned(const Snapshot& snapshot, int object, const math::Pose<double>& goal, const Symmetry& symmetry,
                    const Tolerances& tol = {}) {
  const ObjectState& o = detail::object_at(snapshot, object);
  const std::array<int, 1> one{object};
  if (!detail::released_at_rest(snapshot, one, tol)) return false;
  if ((o.pose.translation - goal.translation).norm() > tol.aln_position) return false;
  return orientation_error(o.pose.rotation, goal.rotation, symmetry) <= tol.aln_orientation;
}

/// STK: `items` from the bottom (largest) to the top (smallest): each item touches the one below,
/// its centre of mass lies higher and within `stk_horizontal` of the one below horizontally, only
/// the bottom item touches the table, all released and at rest (holding it for a while is
/// SuccessTracker's job).
inline bool stacked(const Snapshot& snapshot, std::span<const int> items, const Tolerances& tol = {}) {
  if (items.size() < 2) ::manisoft::detail::fail("a stack needs at least 2 items, got ", items.size());
  if (!detail::released_at_rest(snapshot, items, tol)) return false;
  for (std::size_t k = 1; k < items.size(); ++k) {
    const ObjectState& below = detail::object_at(snapshot, items[k - 1]);
    const ObjectState& above = detail::object_at(snapshot, items[k]);
    if (!above.touches(items[k - 1]) || above.touches_table) return false;
    if (above.center_of_mass.z() <= below.center_of_mass.z()) return false;
    if ((above.center_of_mass - below.center_of_mass).head<2>().norm() > tol.stk_horizontal) return false;
  }
  return true;
}

/// ARR: a spatial relation between objects, in the viewer's words (geometry/spatial_relation.hpp).
struct Relation {
  using Kind = geometry::RelationKind;
  Kind kind = Kind::next_to;
  std::array<int, 4> objects{-1, -1, -1, -1};  ///< left_of..next_to: (a, b) "a <relation> b";
                                               ///< between: (a, b, c) "a between b and c";
                                               ///< in_a_row: 3 or 4 objects, -1 ends the list
  int count() const {
    int n = 0;
    while (n < 4 && objects[static_cast<std::size_t>(n)] >= 0) ++n;
    return n;
  }
};

/// Does the relation hold between the objects' centres of mass (horizontal plane)? Positions only.
inline bool relation_holds(const Snapshot& snapshot, const Relation& relation, const Tolerances& tol = {}) {
  const int n = relation.count();
  const int lo = geometry::relation_min_count(relation.kind), hi = geometry::relation_max_count(relation.kind);
  if (n < lo || n > hi) {
    ::manisoft::detail::fail("relation ", to_string(relation.kind), " needs ", lo, lo == hi ? "" : " or 4", " objects, got ", n);
  }
  std::array<Eigen::Vector2d, 4> centres;
  for (int k = 0; k < n; ++k)
    centres[static_cast<std::size_t>(k)] = detail::object_at(snapshot, relation.objects[static_cast<std::size_t>(k)]).center_of_mass.head<2>();
  return geometry::relation_holds(relation.kind, std::span<const Eigen::Vector2d>(centres.data(), static_cast<std::size_t>(n)), tol.arr);
}

/// ARR: every relation holds, every object named in them released and at rest.
inline bool arranged(const Snapshot& snapshot, std::span<const Relation> relations, const Tolerances& tol = {}) {
  if (relations.empty()) ::manisoft::detail::fail("an arrangement needs at least one relation");
  for (const Relation& r : relations) {
    if (!relation_holds(snapshot, r, tol)) return false;
    const std::span<const int> named(r.objects.data(), static_cast<std::size_t>(r.count()));
    if (!detail::released_at_rest(snapshot, named, tol)) return false;
  }
  return true;
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
