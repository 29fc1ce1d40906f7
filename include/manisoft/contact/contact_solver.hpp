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
// Friction (per contact patch, at the centroid of its points, see PatchFriction): 2D tangential
// impulse, same soft form with bias = bias_rate * drift, where drift is the tangential slip of the
// centroid accumulated since the patch last stuck; clamped to the Coulomb disc
// |lambda_t| <= mu sum(lambda_n), in the direction opposing the slip it leaves (maximum
// dissipation). A clamped patch slides and its drift is reset; a patch inside the disc sticks and
// the anchor spring pulls any creep back: true static friction, no creep on inclines. Twist about
// the normal: the same with a scalar impulse bounded by mu sum(lambda_n) r_twist.
// Rolling resistance (per patch, when the pair's length r_roll > 0): the relative angular velocity
// in the tangent plane is driven to zero by a 2D angular impulse bounded by r_roll sum(lambda_n),
// the torque of the normal force shifted r_roll ahead of the contact as real surfaces deform
// (the rolling-resistance length of engineering tables; ODE, Bullet and MuJoCo model it so).
// Rigid point contact has none: a round base released a hair off flat rolls on its rim forever
// (Euler's disk without its dissipation), and a cylinder on its side rolls on at constant speed.
// Velocity level only (no anchor, no warm start): it removes rolling, it never drives it.
// Relax: the same with bias = 0 (rigid), so the velocity left after the step carries no
// position-correction term. Restitution: after relax, points that approached faster than the
// threshold get lambda such that v_n = -e v_n,before.
// Moving surfaces (a gripper's finger moving within its body): every relative velocity above
// includes the manifold's surface_velocity, so the contact drives the other body at the surface's
// speed instead of letting the surface sink in and pushing it out by penetration recovery.
#pragma once

#include "manisoft/contact/contact_manifold.hpp"

#include <numbers>
#include <span>
#include <vector>

namespace manisoft::contact {

/// The manifolds the solver works on this step: those with points and a moving body, in the
/// world's manifold order (RigidWorld builds the list).
using ActiveManifolds = std::span<ContactManifold* const>;

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

inline Vec3 relative_velocity(const SolverBody& a, const SolverBody& b, const Vec3& ra, const Vec3& rb) {
  return b.v + b.w.cross(rb) - a.v - a.w.cross(ra);
}

inline void apply_impulse(SolverBody& a, SolverBody& b, const Vec3& ra, const Vec3& rb, const Vec3& impulse) {
  a.v -= a.inv_mass * impulse;
  a.w -= a.inv_inertia * ra.cross(impulse);
  b.v += b.inv_mass * impulse;
  b.w += b.inv_inertia * rb.cross(impulse);
}

inline void apply_angular_impulse(SolverBody& a, SolverBody& b, const Vec3& angular) {
  a.w -= a.inv_inertia * angular;
  b.w += b.inv_inertia * angular;
}

}  // namespace detail

/// Prepare: world anchors, current separation, effective masses, restitution speed; friction
/// state projected on the current tangent basis.
template <typename BodyStates>
void prepare_contacts(ActiveManifolds manifolds, const BodyStates& states,
                      const std::vector<SolverBody>& bodies) {
  for (ContactManifold* active : manifolds) {
    auto& m = *active;
    const auto& sa = states[m.body_a];
    const auto& sb = states[m.body_b];
    const auto& ba = bodies[m.body_a];
    const auto& bb = bodies[m.body_b];
    m.normal = (m.owner == NormalOwner::shape_a ? sa.rotation : sb.rotation) * m.normal_local;
    tangent_basis(m.normal, m.tangent1, m.tangent2);
    const Vec3& n = m.normal;
    Vec3 centroid = Vec3::Zero();
    for (int k = 0; k < m.count; ++k) {
      auto& p = m.points[static_cast<std::size_t>(k)];
      const Vec3 pa = sa.position + sa.rotation * p.anchor_a;
      const Vec3 pb = sb.position + sb.rotation * p.anchor_b;
      p.separation = p.base_separation + (pb - pa).dot(n);
      const Vec3 mid = 0.5 * (pa + pb);
      centroid += mid;
      p.ra = mid - sa.position;
      p.rb = mid - sb.position;
      const Vec3 ran = p.ra.cross(n), rbn = p.rb.cross(n);
      const double kn = ba.inv_mass + bb.inv_mass + ran.dot(ba.inv_inertia * ran) + rbn.dot(bb.inv_inertia * rbn);
      p.normal_mass = kn > 0 ? 1.0 / kn : 0.0;
      p.ra_x_n = ran;
      p.rb_x_n = rbn;
      p.ia_ra_x_n = ba.inv_inertia * ran;
      p.ib_rb_x_n = bb.inv_inertia * rbn;
      p.relative_velocity = n.dot(detail::relative_velocity(ba, bb, p.ra, p.rb) + m.surface_velocity);
      p.max_normal_impulse = 0;
    }
    auto& f = m.patch;
    centroid /= static_cast<double>(std::max(m.count, 1));
    f.ra = centroid - sa.position;
    f.rb = centroid - sb.position;
    double spread = 0;
    for (int k = 0; k < m.count; ++k) spread += (m.points[static_cast<std::size_t>(k)].ra - f.ra).norm();
    // Uniform pressure over a disc through the points: mean lever arm 2/3 of their radius.
    f.twist_radius = m.count > 1 ? (2.0 / 3.0) * spread / m.count : 0.0;
    const Vec3 t[2] = {m.tangent1, m.tangent2};
    Vec3 rat[2], rbt[2];
    for (int i = 0; i < 2; ++i) {
      rat[i] = f.ra.cross(t[i]);
      rbt[i] = f.rb.cross(t[i]);
      f.ra_x_t[static_cast<std::size_t>(i)] = rat[i];
      f.rb_x_t[static_cast<std::size_t>(i)] = rbt[i];
      f.ia_ra_x_t[static_cast<std::size_t>(i)] = ba.inv_inertia * rat[i];
      f.ib_rb_x_t[static_cast<std::size_t>(i)] = bb.inv_inertia * rbt[i];
    }
    f.ia_n = ba.inv_inertia * n;
    f.ib_n = bb.inv_inertia * n;
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        f.tangent_k(i, j) = (i == j ? ba.inv_mass + bb.inv_mass : 0.0) + rat[i].dot(ba.inv_inertia * rat[j]) +
                            rbt[i].dot(bb.inv_inertia * rbt[j]);
      }
    }
    const double det = f.tangent_k.determinant();
    f.tangent_mass = det > 0 ? Eigen::Matrix2d(f.tangent_k.inverse()) : Eigen::Matrix2d::Zero();
    const double kw = n.dot(ba.inv_inertia * n) + n.dot(bb.inv_inertia * n);
    f.twist_mass = kw > 0 ? 1.0 / kw : 0.0;
    if (m.rolling_resistance > 0) {
      Eigen::Matrix2d kr;
      for (int i = 0; i < 2; ++i) {
        f.ia_t[static_cast<std::size_t>(i)] = ba.inv_inertia * t[i];
        f.ib_t[static_cast<std::size_t>(i)] = bb.inv_inertia * t[i];
      }
      for (int i = 0; i < 2; ++i) {
        for (int j = 0; j < 2; ++j) {
          kr(i, j) = t[i].dot(f.ia_t[static_cast<std::size_t>(j)] + f.ib_t[static_cast<std::size_t>(j)]);
        }
      }
      f.rolling_mass = kr.determinant() > 0 ? Eigen::Matrix2d(kr.inverse()) : Eigen::Matrix2d::Zero();
    }
    f.rolling_impulse.setZero();
    f.impulse = {t[0].dot(f.tangent_impulse), t[1].dot(f.tangent_impulse)};
    f.drift_2d = {t[0].dot(f.drift), t[1].dot(f.drift)};
    f.sliding = false;
    f.twisting = false;
  }
}

inline void warm_start_contacts(ActiveManifolds manifolds, std::vector<SolverBody>& bodies) {
  for (ContactManifold* active : manifolds) {
    auto& m = *active;
    auto& ba = bodies[m.body_a];
    auto& bb = bodies[m.body_b];
    double total = 0;
    for (int k = 0; k < m.count; ++k) {
      const auto& p = m.points[static_cast<std::size_t>(k)];
      total += p.normal_impulse;
      ba.w -= p.normal_impulse * p.ia_ra_x_n;
      bb.w += p.normal_impulse * p.ib_rb_x_n;
    }
    const auto& f = m.patch;
    const Vec3 linear = total * m.normal + f.impulse[0] * m.tangent1 + f.impulse[1] * m.tangent2;
    ba.v -= ba.inv_mass * linear;
    bb.v += bb.inv_mass * linear;
    ba.w -= f.impulse[0] * f.ia_ra_x_t[0] + f.impulse[1] * f.ia_ra_x_t[1] + f.twist_impulse * f.ia_n;
    bb.w += f.impulse[0] * f.ib_rb_x_t[0] + f.impulse[1] * f.ib_rb_x_t[1] + f.twist_impulse * f.ib_n;
  }
}

/// One Gauss-Seidel pass over the active manifolds: patch friction first (it uses the current normal
/// impulses), then non-penetration point by point. `use_bias` = soft solve; false = relax.
inline void solve_contacts(ActiveManifolds manifolds, std::vector<SolverBody>& bodies,
                           const ContactSolverSettings& s, bool use_bias) {
  const double inv_h = 1.0 / s.h;
  for (ContactManifold* active : manifolds) {
    auto& m = *active;
    auto& ba = bodies[m.body_a];
    auto& bb = bodies[m.body_b];
    const Vec3& n = m.normal;
    double total_normal = 0;
    for (int k = 0; k < m.count; ++k) total_normal += m.points[static_cast<std::size_t>(k)].normal_impulse;
    auto& f = m.patch;
    const double max_friction = m.friction * total_normal;
    // Tangential friction at the centroid (Coulomb disc, anchored when sticking).
    {
      const Vec3 dv_lin = bb.v - ba.v + m.surface_velocity;
      const Eigen::Vector2d vt(m.tangent1.dot(dv_lin) + bb.w.dot(f.rb_x_t[0]) - ba.w.dot(f.ra_x_t[0]),
                               m.tangent2.dot(dv_lin) + bb.w.dot(f.rb_x_t[1]) - ba.w.dot(f.ra_x_t[1]));
      Eigen::Vector2d d_lambda;
      if (use_bias) {
        d_lambda = -s.soft.mass_scale * (f.tangent_mass * (vt + s.soft.bias_rate * f.drift_2d)) - s.soft.impulse_scale * f.impulse;
      } else {
        d_lambda = -(f.tangent_mass * vt);
      }
      Eigen::Vector2d lambda = f.impulse + d_lambda;
      const double mag = lambda.norm();
      const bool clamped = mag > max_friction;
      if (clamped) {
        // Sliding: maximum dissipation, the impulse opposes the slip it leaves,
        // w = v_t + K (lambda - lambda_old); the unconstrained direction K^-1 v_t would not (K is
        // anisotropic off the centre of mass). Fixed-point iterations on |lambda| = mu lambda_n.
        lambda *= mag > 0 ? max_friction / mag : 0.0;
        for (int fp = 0; fp < 3; ++fp) {
          const Eigen::Vector2d slip = vt + f.tangent_k * (lambda - f.impulse);
          const double sn = slip.norm();
          if (!(sn > 1e-12)) break;
          lambda = -(max_friction / sn) * slip;
        }
      }
      if (use_bias) f.sliding = clamped;
      d_lambda = lambda - f.impulse;
      f.impulse = lambda;
      const Vec3 linear = d_lambda[0] * m.tangent1 + d_lambda[1] * m.tangent2;
      ba.v -= ba.inv_mass * linear;
      bb.v += bb.inv_mass * linear;
      ba.w -= d_lambda[0] * f.ia_ra_x_t[0] + d_lambda[1] * f.ia_ra_x_t[1];
      bb.w += d_lambda[0] * f.ib_rb_x_t[0] + d_lambda[1] * f.ib_rb_x_t[1];
    }
    // Twist friction about the normal.
    if (f.twist_radius > 0) {
      const double wn = n.dot(bb.w - ba.w);
      double d_lambda;
      if (use_bias) {
        d_lambda = -s.soft.mass_scale * f.twist_mass * (wn + s.soft.bias_rate * f.twist_drift) - s.soft.impulse_scale * f.twist_impulse;
      } else {
        d_lambda = -f.twist_mass * wn;
      }
      const double limit = max_friction * f.twist_radius;
      const double lambda = std::clamp(f.twist_impulse + d_lambda, -limit, limit);
      if (use_bias) f.twisting = std::abs(f.twist_impulse + d_lambda) > limit;
      ba.w -= (lambda - f.twist_impulse) * f.ia_n;
      bb.w += (lambda - f.twist_impulse) * f.ib_n;
      f.twist_impulse = lambda;
    }
    // Rolling resistance about the tangent axes.
    if (m.rolling_resistance > 0 && total_normal > 0) {
      const Vec3 dw = bb.w - ba.w;
      const Eigen::Vector2d wt(m.tangent1.dot(dw), m.tangent2.dot(dw));
      Eigen::Vector2d lambda = f.rolling_impulse - f.rolling_mass * wt;
      const double limit = m.rolling_resistance * total_normal, mag = lambda.norm();
      if (mag > limit) lambda *= limit / mag;
      const Eigen::Vector2d d_lambda = lambda - f.rolling_impulse;
      f.rolling_impulse = lambda;
      ba.w -= d_lambda[0] * f.ia_t[0] + d_lambda[1] * f.ia_t[1];
      bb.w += d_lambda[0] * f.ib_t[0] + d_lambda[1] * f.ib_t[1];
    }
    // Non-penetration.
    for (int k = 0; k < m.count; ++k) {
      auto& p = m.points[static_cast<std::size_t>(k)];
      const double vn = n.dot(bb.v - ba.v + m.surface_velocity) + bb.w.dot(p.rb_x_n) - ba.w.dot(p.ra_x_n);
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
      ba.v -= (ba.inv_mass * applied) * n;
      ba.w -= applied * p.ia_ra_x_n;
      bb.v += (bb.inv_mass * applied) * n;
      bb.w += applied * p.ib_rb_x_n;
    }
  }
}

/// Between the solve and the relax pass, after positions moved by h v: the separation the relax
/// pass sees (s + h v_n) and the slip added to the static-friction drift (reset when sliding).
inline void update_after_position_integration(ActiveManifolds manifolds, std::vector<SolverBody>& bodies,
                                              const ContactSolverSettings& s) {
  for (ContactManifold* active : manifolds) {
    auto& m = *active;
    const auto& ba = bodies[m.body_a];
    const auto& bb = bodies[m.body_b];
    double total_normal = 0;
    for (int k = 0; k < m.count; ++k) {
      auto& p = m.points[static_cast<std::size_t>(k)];
      p.relax_separation = p.separation + s.h * m.normal.dot(detail::relative_velocity(ba, bb, p.ra, p.rb) + m.surface_velocity);
      total_normal += p.normal_impulse;
    }
    auto& f = m.patch;
    if (f.sliding || total_normal <= 0) {
      f.drift_2d.setZero();
    } else {
      const Vec3 dv = detail::relative_velocity(ba, bb, f.ra, f.rb) + m.surface_velocity;
      f.drift_2d += s.h * Eigen::Vector2d(m.tangent1.dot(dv), m.tangent2.dot(dv));
    }
    if (f.twisting || total_normal <= 0) {
      f.twist_drift = 0;
    } else {
      f.twist_drift += s.h * m.normal.dot(bb.w - ba.w);
    }
  }
}

inline void apply_restitution(ActiveManifolds manifolds, std::vector<SolverBody>& bodies,
                              const ContactSolverSettings& s) {
  for (ContactManifold* active : manifolds) {
    auto& m = *active;
    if (m.restitution == 0) continue;
    auto& ba = bodies[m.body_a];
    auto& bb = bodies[m.body_b];
    for (int k = 0; k < m.count; ++k) {
      auto& p = m.points[static_cast<std::size_t>(k)];
      if (p.relative_velocity > -s.restitution_threshold || p.max_normal_impulse == 0) continue;
      const double vn = m.normal.dot(detail::relative_velocity(ba, bb, p.ra, p.rb) + m.surface_velocity);
      const double impulse = -p.normal_mass * (vn + m.restitution * p.relative_velocity);
      const double lambda = std::max(p.normal_impulse + impulse, 0.0);
      detail::apply_impulse(ba, bb, p.ra, p.rb, (lambda - p.normal_impulse) * m.normal);
      p.normal_impulse = lambda;
    }
  }
}

/// Store: keep the accumulated impulses and drift (world vectors) for the next step.
inline void store_impulses(ActiveManifolds manifolds, const ContactSolverSettings& s) {
  for (ContactManifold* active : manifolds) {
    auto& m = *active;
    auto& f = m.patch;
    if (!s.warm_start) {
      for (int k = 0; k < m.count; ++k) m.points[static_cast<std::size_t>(k)].normal_impulse = 0;
      f.impulse.setZero();
      f.twist_impulse = 0;
    }
    f.tangent_impulse = f.impulse[0] * m.tangent1 + f.impulse[1] * m.tangent2;
    f.drift = f.drift_2d[0] * m.tangent1 + f.drift_2d[1] * m.tangent2;
  }
}

}  // namespace manisoft::contact
