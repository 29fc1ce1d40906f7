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
  Eigen::Matrix2d rolling_mass{Eigen::Matrix2d::Zero()};   ///< inverse of t_i . (Ia^-1 + Ib^-1) t_j
  Eigen::Vector2d rolling_impulse{Eigen::Vector2d::Zero()}; ///< angular, (t1, t2) basis, this step
  std::array<Vec3, 2> ia_t{Vec3::Zero(), Vec3::Zero()}, ib_t{Vec3::Zero(), Vec3::Zero()};
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
  double friction{0.5}, restitution{0}, rolling_resistance{0};
  int count{0};
  std::array<ManifoldPoint, kMaxContactPoints> points{};
  PatchFriction patch{};
  double travel_a{0}, travel_b{0};  ///< body travel when last detected
  bool fresh{true};                 ///< never run through the narrow phase
  bool rolling{false};              ///< last detection was a rolling contact (ContactSet::rolling)
  // Per step.
  Vec3 normal{Vec3::UnitZ()}, tangent1{Vec3::UnitX()}, tangent2{Vec3::UnitY()};
  Vec3 surface_velocity{Vec3::Zero()};  ///< B's surface velocity minus A's, beyond their bodies' motion (world)

  std::uint64_t key() const { return (std::uint64_t(geom_a) << 32) | geom_b; }
};

/// Deterministic tangent basis of a unit normal.
/// The part of a manifold that carries over from one step to the next (cached contact geometry,
/// accumulated impulses, friction drift, re-detection bookkeeping). Every other field is
/// recomputed by prepare_contacts before it is read, so this is all a rollback has to keep.
struct ManifoldMemory {
  std::uint32_t geom_a{0}, geom_b{0}, body_a{0}, body_b{0};
  Vec3 normal_local{Vec3::UnitZ()};
  NormalOwner owner{NormalOwner::shape_a};
  bool fresh{true}, rolling{false};
  int count{0};
  double friction{0.5}, restitution{0}, rolling_resistance{0}, travel_a{0}, travel_b{0};
  struct Point {
    Vec3 anchor_a{Vec3::Zero()}, anchor_b{Vec3::Zero()};
    double base_separation{0}, normal_impulse{0};
  };
  std::array<Point, kMaxContactPoints> points{};
  Vec3 tangent_impulse{Vec3::Zero()}, drift{Vec3::Zero()};
  double twist_impulse{0}, twist_drift{0};

  static ManifoldMemory of(const ContactManifold& m) {
    ManifoldMemory r;
    r.geom_a = m.geom_a;
    r.geom_b = m.geom_b;
    r.body_a = m.body_a;
    r.body_b = m.body_b;
    r.normal_local = m.normal_local;
    r.owner = m.owner;
    r.fresh = m.fresh;
    r.rolling = m.rolling;
    r.count = m.count;
    r.friction = m.friction;
    r.restitution = m.restitution;
    r.rolling_resistance = m.rolling_resistance;
    r.travel_a = m.travel_a;
    r.travel_b = m.travel_b;
    for (int k = 0; k < m.count; ++k) {
      const auto& p = m.points[static_cast<std::size_t>(k)];
      r.points[static_cast<std::size_t>(k)] = {p.anchor_a, p.anchor_b, p.base_separation, p.normal_impulse};
    }
    r.tangent_impulse = m.patch.tangent_impulse;
    r.drift = m.patch.drift;
    r.twist_impulse = m.patch.twist_impulse;
    r.twist_drift = m.patch.twist_drift;
    return r;
  }
  /// A manifold with this memory (per-step fields default; prepare_contacts fills them).
  ContactManifold manifold() const {
    ContactManifold m;
    m.geom_a = geom_a;
    m.geom_b = geom_b;
    m.body_a = body_a;
    m.body_b = body_b;
    m.normal_local = normal_local;
    m.owner = owner;
    m.fresh = fresh;
    m.rolling = rolling;
    m.count = count;
    m.friction = friction;
    m.restitution = restitution;
    m.rolling_resistance = rolling_resistance;
    m.travel_a = travel_a;
    m.travel_b = travel_b;
    for (int k = 0; k < count; ++k) {
      const auto& p = points[static_cast<std::size_t>(k)];
      auto& q = m.points[static_cast<std::size_t>(k)];
      q.anchor_a = p.anchor_a;
      q.anchor_b = p.anchor_b;
      q.base_separation = p.base_separation;
      q.normal_impulse = p.normal_impulse;
    }
    m.patch.tangent_impulse = tangent_impulse;
    m.patch.drift = drift;
    m.patch.twist_impulse = twist_impulse;
    m.patch.twist_drift = twist_drift;
    return m;
  }
};

inline void tangent_basis(const Vec3& n, Vec3& t1, Vec3& t2) {
  if (std::abs(n.x()) >= 0.57735) {
    t1 = Vec3(n.y(), -n.x(), 0.0).normalized();
  } else {
    t1 = Vec3(0.0, n.z(), -n.y()).normalized();
  }
  t2 = n.cross(t1);
}

}  // namespace manisoft::contact
