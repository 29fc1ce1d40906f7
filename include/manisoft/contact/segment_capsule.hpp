// A capsule around a moving segment p0-p1 (a rod element, a swept query), rebuilt every step
// without allocating: the collision shape, its pose (local z along the segment, local x from a
// reference direction such as the element's d1, so the frame follows the material), and the
// segment parameter t in [0, 1] of a point, x = p0 + t (p1 - p0), that splits a contact force on
// the two end nodes. The FCL capsule behind it (for an FCL broad-phase query) is created
// once and resized in place.
#pragma once

#include <algorithm>
#include <memory>

#include "manisoft/contact/collide_primitives.hpp"
#include "manisoft/contact/collision_shape.hpp"

namespace manisoft::contact {

class SegmentCapsule {
 public:
  /// Places the capsule of `radius` around p0-p1; `reference_x` orients the local x axis
  /// (projected off the segment; any perpendicular if it is parallel to it).
  void set(const Vec3& p0, const Vec3& p1, double radius, const Vec3& reference_x) {
    p0_ = p0;
    axis_ = p1 - p0;
    length_ = axis_.norm();
    const Vec3 z = length_ > 0 ? Vec3(axis_ / length_) : reference_x.normalized().cross(detail::any_perpendicular(reference_x));
    Vec3 x = reference_x - z * z.dot(reference_x);
    if (x.squaredNorm() < 1e-12) x = detail::any_perpendicular(z);
    x.normalize();
    pose_.translation = 0.5 * (p0 + p1);
    pose_.rotation.col(0) = x;
    pose_.rotation.col(1) = z.cross(x);
    pose_.rotation.col(2) = z;
    shape_.kind = ShapeKind::capsule;
    shape_.radius = radius;
    shape_.half_length = 0.5 * length_;
    shape_.bounding_radius = radius + 0.5 * length_;
    if (!fcl_capsule_) {
      fcl_capsule_ = std::make_shared<fcl::Capsuled>(radius, length_);
      shape_.fcl_geometry = fcl_capsule_;
    }
    fcl_capsule_->radius = radius;
    fcl_capsule_->lz = length_;
    fcl_capsule_->computeLocalAABB();
  }

  const CollisionShape& shape() const { return shape_; }
  const Pose& pose() const { return pose_; }
  double length() const { return length_; }
  /// t of the point of the segment nearest `x`, clamped to [0, 1] (0 for a zero-length segment).
  double segment_parameter(const Vec3& x) const {
    return length_ > 0 ? std::clamp((x - p0_).dot(axis_) / (length_ * length_), 0.0, 1.0) : 0.0;
  }
  /// The FCL capsule (for a broad-phase query object).
  const std::shared_ptr<fcl::Capsuled>& fcl_capsule() const { return fcl_capsule_; }

 private:
  CollisionShape shape_;
  Pose pose_;
  std::shared_ptr<fcl::Capsuled> fcl_capsule_;
  Vec3 p0_{Vec3::Zero()}, axis_{Vec3::Zero()};
  double length_{0};
};

}  // namespace manisoft::contact
