// Overlap of two oriented boxes by the separating axis theorem (Gottschalk, Lin and Manocha,
// "OBBTree", SIGGRAPH 1996, section 4): two convex boxes are disjoint exactly when their
// projections onto one of 15 axes (the 3 face normals of each box and the 9 cross products of
// their edge directions) are disjoint. A margin grows both boxes by half of it on every side, so
// the test answers "closer than the margin". The planners use it as a cheap clearance check
// between bounding boxes (task/expert.hpp: the held object and the gripper along a carry).
#pragma once

#include <Eigen/Core>

#include <cmath>

#include "manisoft/math/se3.hpp"

namespace manisoft::geometry {

/// Whether two oriented boxes come within `margin` of each other: no separating axis among the
/// 15 of two oriented boxes. Box a has half extents `ha` and centre `ca` in the frame `pa`
/// (frame -> world); box b likewise (`hb`, `cb`, `pb`). Parallel edge pairs (a cross product
/// shorter than 1e-6) give no axis.
inline bool boxes_overlap(const math::Pose<double>& pa, const Eigen::Vector3d& ca, const Eigen::Vector3d& ha, const math::Pose<double>& pb,
                          const Eigen::Vector3d& cb, const Eigen::Vector3d& hb, double margin) {
  using Vec3 = Eigen::Vector3d;
  const Eigen::Matrix3d& ra = pa.rotation;
  const Eigen::Matrix3d& rb = pb.rotation;
  const Vec3 ea = ha + Vec3::Constant(0.5 * margin), eb = hb + Vec3::Constant(0.5 * margin);
  const Vec3 d = pb.act(cb) - pa.act(ca);
  auto separated = [&](const Vec3& axis) {
    if (axis.squaredNorm() < 1e-12) return false;
    const double ra_ = (ra.transpose() * axis).cwiseAbs().dot(ea), rb_ = (rb.transpose() * axis).cwiseAbs().dot(eb);
    return std::abs(axis.dot(d)) > ra_ + rb_;
  };
  for (int i = 0; i < 3; ++i)
    if (separated(ra.col(i)) || separated(rb.col(i))) return false;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (separated(ra.col(i).cross(rb.col(j)))) return false;
  return true;
}

}  // namespace manisoft::geometry
