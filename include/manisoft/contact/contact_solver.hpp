// Contact and Coulomb friction solver: sequential impulses with soft constraints, in the stages of
// Box2D v3's "soft step" (prepare, warm start, solve, integrate positions, relax, restitution,
// store), with true static friction from a tangential anchor.
//
// Why this solver: at the rod's 2e-4 s step, a soft-constraint impulse solver is cheap (a few
// flops per point and iteration, one substep per step), unconditionally stable for the stiffness
// we use (it is implicit Euler on a spring-damper), warm starting makes resting stacks converge
// across steps, and the relax pass removes the position-correction velocity, so contacts do not
// pop or gain energy. A penalty method would need stiff springs and a smaller step to keep
// sinking under 0.5 mm.
//
// Soft constraint (Catto, "Solver2D"/Box2D v3): treat the contact as a spring-damper of
// frequency w = 2 pi f and damping ratio z on the effective mass m. Implicit Euler over a step h,
//   m (v2 - v1) = -h (k C + c v2),  C2 = C1 + h v2,  k = m w^2,  c = 2 m z w,
// gives dv = -(a2/(1+a2)) (v1 + (w/a1) C1) with a1 = 2z + h w, a2 = h w a1, i.e.
//   bias_rate = w/a1, mass_scale = a2/(1+a2), impulse_scale = 1/(1+a2),
// and with accumulated impulse lambda over iterations:
//   d_lambda = -m_eff mass_scale (v_n + bias) - impulse_scale lambda.
// Normal: bias = s/h when s > 0 (speculative: may close the gap, no more), else
// max(bias_rate s, -max_push_velocity); lambda >= 0.
// Friction: 2D tangential impulse, same soft form with bias = bias_rate * drift, where drift is the
// tangential slip accumulated at the point since it last stuck; the impulse is clamped to the
// Coulomb disc |lambda_t| <= mu lambda_n. A clamped point is sliding and its drift is reset; a
// point inside the disc sticks and the anchor spring pulls any creep back: no creep on inclines.
// Relax: the same with bias = 0 (rigid), so the velocity left after the step carries no
// position-correction term. Restitution: after relax, points that approached faster than the
// threshold get lambda such that v_n = -e v_n,before.
#pragma once

#include "manisoft/contact/contact_manifold.hpp"

#include <numbers>
#include <vector>

namespace manisoft::contact {

/// Velocity-level view of a body for the solver (inverse mass/inertia 0 = immovable this step).
struct SolverBody {
  Vec3 v{Vec3::Zero()}, w{Vec3::Zero()};
  double inv_mass{0};
  Mat3 inv_inertia{Mat3::Zero()};
};

struct SoftParameters {
  double bias_rate{0}, mass_scale{1}, impulse_scale{0};

  static SoftParameters make(double hertz, double damping_ratio, double h) {
    SoftParameters p;
    if (hertz <= 0) return p;
    const double omega = 2.0 * std::numbers::pi * hertz;
    const double a1 = 2.0 * damping_ratio + h * omega;
    const double a2 = h * omega * a1;
    const double a3 = 1.0 / (1.0 + a2);
    p.bias_rate = omega / a1;
    p.mass_scale = a2 * a3;
    p.impulse_scale = a3;
    return p;
  }
};

struct ContactSolverSettings {
  double h{2e-4};
  SoftParameters soft{};
  double max_push_velocity{1.0};
  double restitution_threshold{0.2};
  bool warm_start{true};
};

namespace detail {

inline Vec3 relative_velocity(const SolverBody& a, const SolverBody& b, const ManifoldPoint& p) {
  return b.v + b.w.cross(p.rb) - a.v - a.w.cross(p.ra);
}

inline void apply_impulse(SolverBody& a, SolverBody& b, const ManifoldPoint& p, const Vec3& impulse) {
  a.v -= a.inv_mass * impulse;
  a.w -= a.inv_inertia * p.ra.cross(impulse);
  b.v += b.inv_mass * impulse;
  b.w += b.inv_inertia * p.rb.cross(impulse);
}

}  // namespace detail

/// Prepare: world anchors, current separation, effective masses, restitution speed; warm start
/// impulses projected on the current tangent basis.
template <typename BodyStates>
void prepare_contacts(std::vector<ContactManifold>& manifolds, const BodyStates& states,
                      const std::vector<SolverBody>& bodies) {
  for (auto& m : manifolds) {
    if (!m.active) continue;
    const auto& sa = states[m.body_a];
    const auto& sb = states[m.body_b];
    const auto& ba = bodies[m.body_a];
    const auto& bb = bodies[m.body_b];
    m.normal = (m.owner == NormalOwner::shape_a ? sa.rotation : sb.rotation) * m.normal_local;
    tangent_basis(m.normal, m.tangent1, m.tangent2);
    const Vec3& n = m.normal;
    for (int k = 0; k < m.count; ++k) {
      auto& p = m.points[static_cast<std::size_t>(k)];
      const Vec3 wa = sa.rotation * p.anchor_a;
      const Vec3 wb = sb.rotation * p.anchor_b;
      const Vec3 pa = sa.position + wa, pb = sb.position + wb;
      p.separation = p.base_separation + (pb - pa).dot(n);
      const Vec3 mid = 0.5 * (pa + pb);
      p.ra = mid - sa.position;
      p.rb = mid - sb.position;
      const Vec3 ran = p.ra.cross(n), rbn = p.rb.cross(n);
      const double kn = ba.inv_mass + bb.inv_mass + ran.dot(ba.inv_inertia * ran) + rbn.dot(bb.inv_inertia * rbn);
      p.normal_mass = kn > 0 ? 1.0 / kn : 0.0;
      Eigen::Matrix2d kt;
      const Vec3 t[2] = {m.tangent1, m.tangent2};
      Vec3 rat[2], rbt[2];
      for (int i = 0; i < 2; ++i) { rat[i] = p.ra.cross(t[i]); rbt[i] = p.rb.cross(t[i]); }
      for (int i = 0; i < 2; ++i) {
        for (int j = 0; j < 2; ++j) {
          kt(i, j) = (i == j ? ba.inv_mass + bb.inv_mass : 0.0) + rat[i].dot(ba.inv_inertia * rat[j]) +
                     rbt[i].dot(bb.inv_inertia * rbt[j]);
        }
      }
      const double det = kt.determinant();
      p.tangent_mass = det > 0 ? Eigen::Matrix2d(kt.inverse()) : Eigen::Matrix2d::Zero();
      p.relative_velocity = n.dot(detail::relative_velocity(ba, bb, p));
      p.friction_impulse = {t[0].dot(p.tangent_impulse), t[1].dot(p.tangent_impulse)};
      p.drift_2d = {t[0].dot(p.drift), t[1].dot(p.drift)};
      p.max_normal_impulse = 0;
      p.sliding = false;
    }
  }
}

inline void warm_start_contacts(std::vector<ContactManifold>& manifolds, std::vector<SolverBody>& bodies) {
  for (auto& m : manifolds) {
    if (!m.active) continue;
    auto& ba = bodies[m.body_a];
    auto& bb = bodies[m.body_b];
    for (int k = 0; k < m.count; ++k) {
      auto& p = m.points[static_cast<std::size_t>(k)];
      const Vec3 impulse = p.normal_impulse * m.normal + p.friction_impulse[0] * m.tangent1 + p.friction_impulse[1] * m.tangent2;
      detail::apply_impulse(ba, bb, p, impulse);
    }
  }
}

/// One Gauss-Seidel pass over all points: friction first (it uses the current normal impulse),
/// then non-penetration. `use_bias` = soft solve; false = relax (rigid, no position correction).
inline void solve_contacts(std::vector<ContactManifold>& manifolds, std::vector<SolverBody>& bodies,
                           const ContactSolverSettings& s, bool use_bias) {
  const double inv_h = 1.0 / s.h;
  for (auto& m : manifolds) {
    if (!m.active) continue;
    auto& ba = bodies[m.body_a];
    auto& bb = bodies[m.body_b];
    const Vec3& n = m.normal;
    for (int k = 0; k < m.count; ++k) {
      auto& p = m.points[static_cast<std::size_t>(k)];
      // Friction (Coulomb disc, anchored when sticking).
      {
        const Vec3 dv = detail::relative_velocity(ba, bb, p);
        const Eigen::Vector2d vt(m.tangent1.dot(dv), m.tangent2.dot(dv));
        Eigen::Vector2d d_lambda;
        if (use_bias) {
          const Eigen::Vector2d bias = s.soft.bias_rate * p.drift_2d;
          d_lambda = -s.soft.mass_scale * (p.tangent_mass * (vt + bias)) - s.soft.impulse_scale * p.friction_impulse;
        } else {
          d_lambda = -(p.tangent_mass * vt);
        }
        Eigen::Vector2d lambda = p.friction_impulse + d_lambda;
        const double max_friction = m.friction * p.normal_impulse;
        const double mag = lambda.norm();
        if (mag > max_friction) {
          lambda *= mag > 0 ? max_friction / mag : 0.0;
          if (use_bias) p.sliding = true;
        }
        d_lambda = lambda - p.friction_impulse;
        p.friction_impulse = lambda;
        detail::apply_impulse(ba, bb, p, d_lambda[0] * m.tangent1 + d_lambda[1] * m.tangent2);
      }
      // Non-penetration.
      {
        const double vn = n.dot(detail::relative_velocity(ba, bb, p));
        const double sep = use_bias ? p.separation : p.relax_separation;
        double bias = 0, mass_scale = 1, impulse_scale = 0;
        if (sep > 0) {
          bias = sep * inv_h;
        } else if (use_bias) {
          bias = std::max(s.soft.bias_rate * sep, -s.max_push_velocity);
          mass_scale = s.soft.mass_scale;
          impulse_scale = s.soft.impulse_scale;
        }
        const double impulse = -p.normal_mass * mass_scale * (vn + bias) - impulse_scale * p.normal_impulse;
        const double lambda = std::max(p.normal_impulse + impulse, 0.0);
        const double applied = lambda - p.normal_impulse;
        p.normal_impulse = lambda;
        p.max_normal_impulse = std::max(p.max_normal_impulse, applied);
        detail::apply_impulse(ba, bb, p, applied * n);
      }
    }
  }
}

/// Between the solve and the relax pass, after positions moved by h v: the separation the relax
/// pass sees (s + h v_n) and the tangential slip added to the static-friction drift.
inline void update_after_position_integration(std::vector<ContactManifold>& manifolds, std::vector<SolverBody>& bodies,
                                              const ContactSolverSettings& s) {
  for (auto& m : manifolds) {
    if (!m.active) continue;
    const auto& ba = bodies[m.body_a];
    const auto& bb = bodies[m.body_b];
    for (int k = 0; k < m.count; ++k) {
      auto& p = m.points[static_cast<std::size_t>(k)];
      const Vec3 dv = detail::relative_velocity(ba, bb, p);
      p.relax_separation = p.separation + s.h * m.normal.dot(dv);
      if (p.sliding || p.normal_impulse <= 0) {
        p.drift_2d.setZero();
      } else {
        p.drift_2d += s.h * Eigen::Vector2d(m.tangent1.dot(dv), m.tangent2.dot(dv));
      }
    }
  }
}

inline void apply_restitution(std::vector<ContactManifold>& manifolds, std::vector<SolverBody>& bodies,
                              const ContactSolverSettings& s) {
  for (auto& m : manifolds) {
    if (!m.active || m.restitution == 0) continue;
    auto& ba = bodies[m.body_a];
    auto& bb = bodies[m.body_b];
    for (int k = 0; k < m.count; ++k) {
      auto& p = m.points[static_cast<std::size_t>(k)];
      if (p.relative_velocity > -s.restitution_threshold || p.max_normal_impulse == 0) continue;
      const double vn = m.normal.dot(detail::relative_velocity(ba, bb, p));
      const double impulse = -p.normal_mass * (vn + m.restitution * p.relative_velocity);
      const double lambda = std::max(p.normal_impulse + impulse, 0.0);
      detail::apply_impulse(ba, bb, p, (lambda - p.normal_impulse) * m.normal);
      p.normal_impulse = lambda;
    }
  }
}

/// Store: keep the accumulated impulses (world tangent vector) and drift for the next step.
inline void store_impulses(std::vector<ContactManifold>& manifolds, const ContactSolverSettings& s) {
  for (auto& m : manifolds) {
    if (!m.active) continue;
    for (int k = 0; k < m.count; ++k) {
      auto& p = m.points[static_cast<std::size_t>(k)];
      if (!s.warm_start) {
        p.normal_impulse = 0;
        p.friction_impulse.setZero();
      }
      p.tangent_impulse = p.friction_impulse[0] * m.tangent1 + p.friction_impulse[1] * m.tangent2;
      p.drift = p.drift_2d[0] * m.tangent1 + p.drift_2d[1] * m.tangent2;
    }
  }
}

}  // namespace manisoft::contact
