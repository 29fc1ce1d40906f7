// Persistent contact manifold of one shape pair: up to 4 points anchored in both bodies, so their
// separation can be extrapolated step after step from the bodies' motion without re-running the
// narrow phase (s = s0 + (p_B - p_A) . n, with p_A, p_B the material points that coincided at
// detection and n attached to the body that owns the contact face: exact for a vertex on a face).
// Re-detected points are matched to cached ones by proximity, carrying over their accumulated
// normal impulses (warm start); the patch friction state (impulse, static-friction drift) stays
// with the manifold while its normal keeps its direction.
#pragma once

#include "manisoft/contact/contact_point.hpp"

#include <Eigen/Core>

namespace manisoft::contact {

struct ManifoldPoint {
  // Cached geometry (from the last narrow-phase run).
  Vec3 anchor_a{Vec3::Zero()}, anchor_b{Vec3::Zero()};  ///< body-local, relative to each COM
  double base_separation{0};
  // Persistent solver data.
  double normal_impulse{0};  ///< accumulated, N s
  double max_normal_impulse{0};
  // Per-step solver data.
  Vec3 ra{Vec3::Zero()}, rb{Vec3::Zero()};  ///< contact point relative to each COM, world
  double separation{0}, relax_separation{0};
  double normal_mass{0};
  double relative_velocity{0};  ///< normal approach speed before the step (restitution)
  // Jacobian rows and their images through the inverse inertia (no 3x3 products in iterations).
  Vec3 ra_x_n{Vec3::Zero()}, rb_x_n{Vec3::Zero()}, ia_ra_x_n{Vec3::Zero()}, ib_rb_x_n{Vec3::Zero()};
};

/// Friction acts on the contact patch as a whole, at the centroid of its points: a 2D tangential
/// impulse bounded by mu * sum(lambda_n) and a twist impulse about the normal bounded by
/// mu * sum(lambda_n) * twist_radius. Per-point friction anchors would fight each other (each
/// point's anchor resets at a different time), load the patch internally and make it creep.
struct PatchFriction {
  // Persistent.
  Vec3 tangent_impulse{Vec3::Zero()};  ///< accumulated, world
  Vec3 drift{Vec3::Zero()};            ///< tangential slip of the centroid since the patch stuck, world
  double twist_impulse{0}, twist_drift{0};
  // Per step.
  Vec3 ra{Vec3::Zero()}, rb{Vec3::Zero()};
  Eigen::Matrix2d tangent_mass{Eigen::Matrix2d::Zero()};  ///< K_t^-1
  Eigen::Matrix2d tangent_k{Eigen::Matrix2d::Zero()};     ///< K_t
  Eigen::Vector2d impulse{Eigen::Vector2d::Zero()};       ///< in the (t1, t2) basis
  Eigen::Vector2d drift_2d{Eigen::Vector2d::Zero()};
  double twist_mass{0}, twist_radius{0};
  bool sliding{false}, twisting{false};
  std::array<Vec3, 2> ra_x_t{Vec3::Zero(), Vec3::Zero()}, rb_x_t{Vec3::Zero(), Vec3::Zero()};
  std::array<Vec3, 2> ia_ra_x_t{Vec3::Zero(), Vec3::Zero()}, ib_rb_x_t{Vec3::Zero(), Vec3::Zero()};
  Vec3 ia_n{Vec3::Zero()}, ib_n{Vec3::Zero()};
};

struct ContactManifold {
  std::uint32_t geom_a{0}, geom_b{0};  ///< geom_a < geom_b
  std::uint32_t body_a{0}, body_b{0};
  Vec3 normal_local{Vec3::UnitZ()};    ///< in the owner body's frame, pointing from A to B
  NormalOwner owner{NormalOwner::shape_a};
  double friction{0.5}, restitution{0};
  int count{0};
  std::array<ManifoldPoint, kMaxContactPoints> points{};
  PatchFriction patch{};
  double travel_a{0}, travel_b{0};  ///< body travel when last detected
  bool fresh{true};                 ///< never run through the narrow phase
  bool rolling{false};              ///< last detection was a rolling contact (ContactSet::rolling)
  // Per step.
  Vec3 normal{Vec3::UnitZ()}, tangent1{Vec3::UnitX()}, tangent2{Vec3::UnitY()};
  bool active{false};

  std::uint64_t key() const { return (std::uint64_t(geom_a) << 32) | geom_b; }
};

/// Deterministic tangent basis of a unit normal.
inline void tangent_basis(const Vec3& n, Vec3& t1, Vec3& t2) {
  if (std::abs(n.x()) >= 0.57735) {
    t1 = Vec3(n.y(), -n.x(), 0.0).normalized();
  } else {
    t1 = Vec3(0.0, n.z(), -n.y()).normalized();
  }
  t2 = n.cross(t1);
}

}  // namespace manisoft::contact
