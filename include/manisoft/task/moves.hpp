// What a task's expert plan is made of (paper section 3.4): a task is a list of moves "put
// object i at pose P" (asset frame -> world), each read from the scene as it stands when the
// move starts. Every task type (coll.hpp ... ovr.hpp) states its moves through this vocabulary:
// `moves(spec)` (how many), `move(k, scene)` (move k's object and target pose), `support(k,
// spec)` (what the object goes into or onto) and `states_yaw` (whether the target's yaw is part
// of the goal); the expert (expert.hpp) reaches them through the registry (registry.hpp) and
// plans the grasps and paths that carry them out.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cstddef>
#include <numbers>

#include "manisoft/assets/asset.hpp"
#include "manisoft/math/se3.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "manisoft/task/success.hpp"

namespace manisoft::task {

/// One move: the object and its target pose (asset frame -> world) when it is released.
struct Move {
  int object = -1;
  math::Pose<double> target;
};

/// How a move's object rests on what it is put on, which decides how it is lowered.
enum class SupportKind {
  table,  ///< on the table
  into,   ///< into a container (its receptacle): lowered into it below the rim
  onto,   ///< onto another item (a stack): let go with the fingers above the item below
};

/// What move k puts its object into or onto: the object (-1: the table) and how.
struct Support {
  int object = -1;
  SupportKind kind = SupportKind::table;
};

/// The scene as a task's moves read it: the spec, the assets, the objects as they stand now, and
/// the clearance of the object's bottom above its support at release.
struct MoveScene {
  const scene::SceneSpec& spec;
  const scene::AssetLibrary& library;
  const Snapshot& snapshot;
  double place_clearance;  ///< m

  const assets::Asset& asset(int object) const {
    return library.get(spec.objects.at(static_cast<std::size_t>(object)).asset_id, "expert object");
  }
  const math::Pose<double>& pose(int object) const { return snapshot.objects[static_cast<std::size_t>(object)].pose; }
};

/// The goal orientation's symmetric equivalent that turns least from `now` (about world z).
inline Eigen::Matrix3d nearest_equivalent(const Eigen::Matrix3d& now, const Eigen::Matrix3d& goal, const scene::Symmetry& sym) {
  if (sym.kind == scene::Symmetry::Kind::axial)  // only the axis matters: `now` turned least to the goal's axis
    return Eigen::Quaterniond::FromTwoVectors(now.col(2), goal.col(2)).toRotationMatrix() * now;
  const int n = sym.kind == scene::Symmetry::Kind::discrete ? std::max(1, sym.order) : 1;
  Eigen::Matrix3d best = goal;
  double best_angle = 10;
  for (int k = 0; k < n; ++k) {
    const Eigen::Matrix3d g = goal * Eigen::AngleAxisd(2 * std::numbers::pi * k / n, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const double a = Eigen::AngleAxisd(g * now.transpose()).angle();
    if (a < best_angle) best_angle = a, best = g;
  }
  return best;
}

}  // namespace manisoft::task
