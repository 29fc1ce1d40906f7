// Rod-contact policies of SoftArmWorld (the arm touching the table, obstacles and objects): every rod element is a
// capsule (nodes k, k + 1, the rod's radius) that touches the rigid bodies of the world (table,
// obstacles, objects) through a penalty force with damping and Coulomb friction with static
// friction (a tangential stick-slip spring, Cundall & Strack 1979).
// The force at a contact point goes to the element's two nodes split by the segment parameter t
// ((1 - t) on node k, t on node k + 1), its moment about the rod axis to the element (material
// frame), and the opposite force to the body at the contact point (RigidWorld::add_force_at_point).
//
// Contact law at a point with penetration depth p = -separation > 0, unit normal n (rod -> body),
// relative velocity v = v_rod - v_body of the two material points (rod: (1-t) v_k + t v_{k+1} +
// omega x r, body: v + w x r), v_n = v . n, v_t = v - v_n n:
//   normal    f_n = max(0, k p + c v_n),                         force on the rod  -f_n n
//   friction  f_t* = -(k_t d_t + c_t v_t)                         (trial, on the rod)
//             f_t  = f_t*                     if |f_t*| <= mu f_n  (stick)
//             f_t  = mu f_n f_t* / |f_t*|     otherwise            (kinetic slip)
// mu = sqrt(mu_rod mu_body) (as rigid pairs). d_t is the tangential separation of the two sides
// of the contact: a rod material point x_r (segment parameter t_a of element k plus the surface
// offset r_a in the element's material frame) and a body anchor x_a (in the body's frame, so it
// moves with the body), d = x_r - x_a, d_t = d - (d . n) n. When a point first appears (element
// k, geometry g, point slot i of the narrow phase) x_a = x_r and d_t = 0. On slip the anchor is
// slid so that the spring alone sits on the Coulomb cone, d_t <- -f_t / k_t (|k_t d_t| = mu f_n,
// along the slip), so sliding resumes at once when the load reverses. After every step the
// anchor is re-based onto the current contact point c keeping d_t (x_r <- c, x_a <- c - d_t),
// so d_t grows by exactly the relative motion of the two material points over the next step
// (v_t dt for small steps) even when the contact point wanders over the rod's surface (rolling,
// a tilting element switching between one and two points). A tangentially loaded contact below
// the Coulomb limit holds at the spring's elastic pre-slip |d_t| = F_t / k_t (micrometres) with
// no creep; above it, it slides with Coulomb friction. Anchors of points that disappear (no
// penetration in an apply()) are dropped. Storage: kAnchorSlots per element, sized at the first
// apply(); a point that finds all of its element's slots taken by live anchors (more than
// kAnchorSlots points on one element) gets no spring this step (f_t* = -c_t v_t, capped).
//
// Stiffness and stability (explicit forces, dt = 2e-4 s). Per point, m_eff = 1 / (1/m_rod + 1/m_b)
// with 1/m_rod = (1-t)^2/m_k + t^2/m_{k+1} + r^2/J_3 (the twist of the element moves its surface)
// and 1/m_b = 1/m + |r_b|^2 |I^-1| (0 for a static body). The nominal stiffness k = 1e5 N/m per
// point keeps the penetration under the whole arm's weight (7.85 kg, 77 N) on one element (two
// points) at 0.39 mm; a rod lying on the table sinks 0.02 mm. It is capped per point at
// k <= m_eff (omega_max / dt)^2 with omega_max dt = 0.3 (a node carries up to four points: two
// elements, two points each, so omega dt <= 0.6, far below the leapfrog limit 2). For an interior
// node on a static table omega dt = sqrt(1e5 / 0.13) 2e-4 = 0.18 (uncapped). Damping is
// c = 2 zeta sqrt(k m_eff) with zeta = 1 (critical: c dt / m_eff = 2 omega dt <= 0.6).
// The tangential spring is the same oscillator in the tangent plane: k_t = min(ratio_t k_nominal,
// m_eff (omega_max / dt)^2) with ratio_t = 1 (so omega_t dt <= 0.3 per point, <= 0.6 per node
// with four points, as the normal), c_t = 2 zeta_t sqrt(k_t m_eff) with zeta_t = 1 (critical: an
// elastic pre-slip rings down in a period instead of oscillating, c_t dt / m_eff <= 0.6). The
// tangential and normal springs act along orthogonal directions, so each keeps its own margin.
// Elastic pre-slip of a rod lying on a table under a sideways load F: F / (40 k_t) = 2.5e-7 m/N.
//
// Broad phase (the world step budget is ~10 us): element AABBs (inflated by radius + margin) and
// their union; a body is skipped unless its bounding sphere's box meets the union; a geometry
// unless its bounds meet the union; then each element whose box meets the geometry's bounds goes
// to the narrow phase (contact/narrow_phase.hpp: analytic capsule-sphere/capsule/box, SAT is not
// used for capsules, support-function GJK/EPA for capsule vs cylinder or mesh). No heap
// allocation in steady state, as in RigidWorld. The anchors are looked up by (geometry, slot) in
// the element's slots in a fixed order: deterministic.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "manisoft/contact/mixing.hpp"
#include "manisoft/contact/narrow_phase.hpp"
#include "manisoft/contact/segment_capsule.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/interaction/stable_spring.hpp"
#include "manisoft/rigid/rigid_world.hpp"

namespace manisoft::interaction {

/// No contact between rod elements and bodies (a free-space arm).
struct NoRodContact {
  struct Snapshot {};
  template <typename Rod>
  void apply(Rod&, rigid::RigidWorld&) {}
  void save(Snapshot&, bool) const {}
  void restore(const Snapshot&) {}
};

struct RodContactParameters {
  double stiffness = 1e5;          ///< k, N/m per contact point (nominal; capped for stability)
  double damping_ratio = 1.0;      ///< zeta of the normal spring on the point's effective mass
  double friction = 0.6;           ///< mu of the rod surface (pairs: sqrt(mu_rod mu_body))
  double tangential_stiffness_ratio = 1.0;  ///< k_t / k of the stick-slip spring (capped as k)
  double tangential_damping_ratio = 1.0;    ///< zeta_t of the stick-slip spring on m_eff
  double max_omega_dt = 0.3;       ///< stiffness cap: sqrt(k / m_eff) dt <= this
  double margin = 1e-3;            ///< m: broad-phase inflation of element boxes

  void validate() const {
    manisoft::detail::require_positive("rod_contact stiffness", stiffness);
    manisoft::detail::require_non_negative("rod_contact damping_ratio", damping_ratio);
    manisoft::detail::require_non_negative("rod_contact friction", friction);
    manisoft::detail::require_non_negative("rod_contact tangential_stiffness_ratio", tangential_stiffness_ratio);
    manisoft::detail::require_non_negative("rod_contact tangential_damping_ratio", tangential_damping_ratio);
    if (!(tangential_damping_ratio <= 1.0))
      manisoft::detail::fail("rod_contact tangential_damping_ratio = ", tangential_damping_ratio, " must be <= 1 (explicit stability)");
    manisoft::detail::require_positive("rod_contact max_omega_dt", max_omega_dt);
    if (!(max_omega_dt <= 0.5)) manisoft::detail::fail("rod_contact max_omega_dt = ", max_omega_dt, " must be <= 0.5 (explicit stability)");
    manisoft::detail::require_non_negative("rod_contact margin", margin);
  }
};

/// One active contact point of the last step (for tests, traces and statistics).
struct RodContactPoint {
  int element = 0;
  rigid::BodyId body = 0;
  std::uint32_t geom = 0;
  double segment_parameter = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< world, between the surfaces
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   ///< from the rod into the body
  double separation = 0;                               ///< < 0: penetration
  double normal_force = 0;                             ///< f_n >= 0 [N]
  Eigen::Vector3d force_on_rod = Eigen::Vector3d::Zero();  ///< -f_n n + f_t [N], lab
  bool sticking = false;  ///< friction inside the Coulomb cone (static), else sliding
};

/// Rod elements as capsules against every body of the world (see the header comment).
class RodCapsuleContact {
 public:
  using Vec3 = Eigen::Vector3d;
  /// Stick-slip anchors kept per rod element (points of all geometries touching it).
  static constexpr int kAnchorSlots = 8;

  RodCapsuleContact() = default;
  explicit RodCapsuleContact(const RodContactParameters& p) : params_(p) { params_.validate(); }

  const RodContactParameters& parameters() const { return params_; }

  /// The rod does not touch body `id` (e.g. the end-effector it is coupled to).
  void exclude(rigid::BodyId id) {
    if (std::find(excluded_.begin(), excluded_.end(), id) == excluded_.end()) excluded_.push_back(id);
  }
  void include(rigid::BodyId id) { excluded_.erase(std::remove(excluded_.begin(), excluded_.end(), id), excluded_.end()); }
  bool is_excluded(rigid::BodyId id) const { return std::find(excluded_.begin(), excluded_.end(), id) != excluded_.end(); }

  /// Drops every friction anchor (e.g. after teleporting the rod or a body): the next apply()
  /// starts every contact unloaded.
  void forget_anchors() {
    for (auto& a : anchors_) a.seen = 0;
  }

  /// Stick-slip anchor of one contact point (see the header comment): the rod material point
  /// (segment parameter, surface offset in the element's material frame) and the body point (body
  /// frame, about the centre of mass) whose tangential separation is the spring's extension.
  struct Anchor {
    std::uint64_t seen = 0;  ///< apply() pass that last used it (live if the previous one)
    std::uint32_t geom = 0;
    int slot = 0;            ///< point index in the narrow phase's contact set
    double segment_parameter = 0;
    Vec3 rod_offset_material = Vec3::Zero();
    Vec3 body_point = Vec3::Zero();
  };

  /// The friction anchors, for rollback. A full snapshot copies them; a step snapshot
  /// (`full` = false, what SoftArmWorld takes before every step) records only the pass counter and
  /// relies on the undo record apply() keeps of the anchors it changes, so it costs nothing.
  struct Snapshot {
    std::uint64_t pass = 1;
    bool full = false;
    std::vector<Anchor> anchors;
  };
  void save(Snapshot& out, bool full) const {
    out.pass = pass_;
    out.full = full;
    if (full) out.anchors = anchors_;
  }
  /// Puts the anchors back to `in`: a full snapshot from any time, a step snapshot only across
  /// the one apply() since it was taken.
  void restore(const Snapshot& in) {
    if (in.full) {
      anchors_ = in.anchors;
    } else if (in.pass + 1 == pass_) {
      for (auto it = undo_.rbegin(); it != undo_.rend(); ++it) *it->anchor = it->before;
      std::swap(contacts_, previous_contacts_);
      narrow_calls_ = previous_narrow_calls_;
      max_penetration_ = previous_max_penetration_;
    } else if (in.pass != pass_) {
      manisoft::detail::fail("RodCapsuleContact::restore: a step snapshot undoes one apply(), ", pass_ - in.pass, " ran since");
    }
    if (in.full) contacts_.clear();  // a report of another time is not restored
    undo_.clear();
    pass_ = in.pass;
  }

  /// Contact points of the last apply() that carried a force.
  const std::vector<RodContactPoint>& contacts() const { return contacts_; }
  /// Narrow-phase calls in the last apply() (broad-phase efficiency).
  int narrow_phase_calls() const { return narrow_calls_; }
  /// Deepest penetration of the last apply() [m] (0 when nothing touches).
  double max_penetration() const { return max_penetration_; }
  /// Sum of the forces on the rod in the last apply() (lab) [N].
  Vec3 total_force_on_rod() const {
    Vec3 f = Vec3::Zero();
    for (const auto& c : contacts_) f += c.force_on_rod;
    return f;
  }

  template <typename Rod>
  void apply(Rod& rod, rigid::RigidWorld& world) {
    const auto& model = rod.model();
    auto& state = rod.state();
    const int n = rod.n_elements();
    const double dt = double(rod.dt());
    const double radius = rod_radius(model);
    const double pad = radius + params_.margin;
    // The last apply()'s report is kept for a step rollback (restore() swaps it back).
    std::swap(contacts_, previous_contacts_);
    contacts_.clear();
    previous_narrow_calls_ = narrow_calls_;
    previous_max_penetration_ = max_penetration_;
    narrow_calls_ = 0;
    max_penetration_ = 0;
    // Anchors seen in the previous apply() (seen == pass_ - 1) are live; older ones are free.
    ++pass_;
    if (anchors_.size() != std::size_t(n) * kAnchorSlots) {
      anchors_.assign(std::size_t(n) * kAnchorSlots, Anchor{});
      undo_.reserve(anchors_.size());
    }
    undo_.clear();

    element_lo_.resize(std::size_t(n));
    element_hi_.resize(std::size_t(n));
    Vec3 rod_lo = Vec3::Constant(INFINITY), rod_hi = Vec3::Constant(-INFINITY);
    for (int k = 0; k < n; ++k) {
      const Vec3 a = state.position(k), b = state.position(k + 1);
      element_lo_[std::size_t(k)] = a.cwiseMin(b) - Vec3::Constant(pad);
      element_hi_[std::size_t(k)] = a.cwiseMax(b) + Vec3::Constant(pad);
      rod_lo = rod_lo.cwiseMin(element_lo_[std::size_t(k)]);
      rod_hi = rod_hi.cwiseMax(element_hi_[std::size_t(k)]);
    }
    if (!rod_lo.allFinite() || !rod_hi.allFinite()) return;  // the rod step reports the bad node

    const auto& geoms = world.geoms();
    for (rigid::BodyId b = 0; b < world.body_count(); ++b) {
      if (is_excluded(b)) continue;
      const auto& bm = world.model(b);
      const Vec3 c = world.center_of_mass(b);
      const Vec3 r = Vec3::Constant(bm.bounding_radius);
      if (!overlaps(c - r, c + r, rod_lo, rod_hi)) continue;
      for (std::uint32_t g = bm.first_geom; g < bm.first_geom + bm.geom_count; ++g) {
        const contact::Pose gp = world.geom_pose(g);
        Vec3 glo, ghi;
        geoms[g].shape.bounds(gp, glo, ghi);
        if (!overlaps(glo, ghi, rod_lo, rod_hi)) continue;
        for (int k = 0; k < n; ++k) {
          if (!overlaps(glo, ghi, element_lo_[std::size_t(k)], element_hi_[std::size_t(k)])) continue;
          collide_element(rod, world, k, b, g, gp, radius, dt);
        }
      }
    }
  }

 private:

  /// The live anchor of (element k, geometry g, point slot i), else a free slot for it (marked
  /// new by seen != pass_ - 1), else nullptr (all slots held by live anchors).
  Anchor* find_anchor(int k, std::uint32_t g, int i) {
    Anchor* first = anchors_.data() + std::size_t(k) * kAnchorSlots;
    Anchor* free_slot = nullptr;
    for (Anchor* a = first; a != first + kAnchorSlots; ++a) {
      if (a->seen + 1 == pass_) {
        if (a->geom == g && a->slot == i) return a;
      } else if (a->seen != pass_ && free_slot == nullptr) {
        free_slot = a;
      }
    }
    return free_slot;
  }

  static bool overlaps(const Vec3& alo, const Vec3& ahi, const Vec3& blo, const Vec3& bhi) {
    return (alo.array() <= bhi.array()).all() && (blo.array() <= ahi.array()).all();
  }

  template <typename Model>
  static double rod_radius(const Model& model) {
    // A = pi r^2 of the first element (the arm is uniform).
    return std::sqrt(double(model.cross_section_area[0]) / 3.14159265358979323846);
  }

  /// Effective mass of the rod-body pair at a contact point (see the header comment).
  template <typename Model>
  static double effective_mass(const Model& model, int k, double t, double radius, const rigid::RigidBodyModel& bm,
                               const rigid::RigidBodyState& bs, const Vec3& point) {
    double inv_m = (1 - t) * (1 - t) * double(model.inv_node_masses[k]) + t * t * double(model.inv_node_masses[k + 1]) +
                   radius * radius / double(model.inertia(k, 2));
    if (!bm.is_static) inv_m += bm.inverse_mass + (point - bs.position).squaredNorm() * bm.inverse_inertia.norm();
    return 1.0 / inv_m;
  }

  /// Tangential separation d_t of a live anchor's two material points (zero for a new point).
  template <typename State>
  Vec3 anchor_separation(const Anchor* anchor, const State& state, int k, const Eigen::Matrix3d& q, const rigid::RigidBodyState& bs,
                         const Vec3& n) const {
    if (anchor == nullptr || anchor->seen + 1 != pass_) return Vec3::Zero();
    const double ta = anchor->segment_parameter;
    const Vec3 x_r = (1 - ta) * state.position(k) + ta * state.position(k + 1) + q.transpose() * anchor->rod_offset_material;
    const Vec3 x_a = bs.position + bs.rotation * anchor->body_point;
    const Vec3 d = x_r - x_a;
    return d - d.dot(n) * n;
  }

  /// Stage 1: the capsule of element k (local x from its d1) against geometry g.
  template <typename Rod>
  void collide_element(Rod& rod, rigid::RigidWorld& world, int k, rigid::BodyId body, std::uint32_t g, const contact::Pose& gp,
                       double radius, double dt) {
    const auto& state = rod.state();
    const Eigen::Matrix3d q = state.director(k);  // rows d1, d2, d3
    capsule_.set(state.position(k), state.position(k + 1), radius, q.row(0).transpose());
    ++narrow_calls_;
    if (!contact::collide(capsule_.shape(), capsule_.pose(), world.geoms()[g].shape, gp, 0.0, set_, scratch_)) return;
    const double mu = contact::mix_friction(params_.friction, world.model(body).friction);
    for (int i = 0; i < set_.count; ++i) {
      if (set_.points[std::size_t(i)].separation < 0) contact_point(rod, world, k, body, g, i, q, radius, mu, dt);
    }
  }

  /// Stage 2: the contact law at point i of the set (normal spring-damper, stick-slip friction),
  /// stage 3: the forces on the two nodes, the element and the body, and the report.
  template <typename Rod>
  void contact_point(Rod& rod, rigid::RigidWorld& world, int k, rigid::BodyId body, std::uint32_t g, int i, const Eigen::Matrix3d& q,
                     double radius, double mu, double dt) {
    const auto& model = rod.model();
    auto& state = rod.state();
    const auto& bm = world.model(body);
    const auto& bs = world.state(body);
    const auto& cp = set_.points[std::size_t(i)];
    const Vec3 n_lab = set_.normal;  // from the capsule (a) into the body (b)
    const double t = capsule_.segment_parameter(cp.position);
    const Vec3 arm = cp.position - (state.position(k) + t * (state.position(k + 1) - state.position(k)));  // rod axis -> point
    const Vec3 omega_lab = q.transpose() * state.angular_velocity(k);
    const Vec3 v_rod = (1 - t) * state.velocity(k) + t * state.velocity(k + 1) + omega_lab.cross(arm);
    const Vec3 v_rel = v_rod - world.velocity_at_point(body, cp.position);
    const double m_eff = effective_mass(model, k, t, radius, bm, bs, cp.position);
    // Normal: f_n = max(0, k p + c v_n).
    const double stiffness = stable_stiffness(params_.stiffness, m_eff, params_.max_omega_dt, dt);
    const double damping = damping_for_ratio(params_.damping_ratio, stiffness, m_eff);
    const double depth = -cp.separation;
    const double vn = v_rel.dot(n_lab);  // > 0: approaching
    const double fn = std::max(0.0, stiffness * depth + damping * vn);
    max_penetration_ = std::max(max_penetration_, depth);
    // Friction: f_t* = -(k_t d_t + c_t v_t), on the Coulomb cone if |f_t*| > mu f_n.
    const Vec3 vt = v_rel - vn * n_lab;
    Anchor* anchor = find_anchor(k, g, i);
    Vec3 d_tan = anchor_separation(anchor, state, k, q, bs, n_lab);
    const double k_t = stable_stiffness(params_.tangential_stiffness_ratio * params_.stiffness, m_eff, params_.max_omega_dt, dt);
    const double c_t = damping_for_ratio(params_.tangential_damping_ratio, k_t, m_eff);
    Vec3 ft = anchor == nullptr ? Vec3(-c_t * vt) : Vec3(-(k_t * d_tan + c_t * vt));
    const double ft_norm = ft.norm();
    const double ft_max = mu * fn;
    const bool sticking = ft_norm <= ft_max;
    if (!sticking) {
      ft *= ft_max / ft_norm;                             // kinetic: |f_t| = mu f_n, along f_t*
      d_tan = k_t > 0 ? Vec3(-ft / k_t) : Vec3::Zero();  // anchor slid: the spring on the cone
    }
    const Vec3 f_rod = -fn * n_lab + ft;
    if (anchor != nullptr) {
      // Re-base onto the current contact point c = axis point + arm, keeping d_t.
      if (undo_.size() < undo_.capacity()) undo_.push_back({anchor, *anchor});
      anchor->seen = pass_;
      anchor->geom = g;
      anchor->slot = i;
      anchor->segment_parameter = t;
      anchor->rod_offset_material = q * arm;
      anchor->body_point = bs.rotation.transpose() * (cp.position - d_tan - bs.position);
    }
    if (fn == 0) return;
    // Rod: nodes by the segment parameter, the moment of the force about the axis to the element.
    state.external_forces.row(k) += ((1 - t) * f_rod).transpose();
    state.external_forces.row(k + 1) += (t * f_rod).transpose();
    state.external_torques.row(k) += (q * arm.cross(f_rod)).transpose();
    // Body: the opposite force at the contact point.
    world.add_force_at_point(body, -f_rod, cp.position);
    RodContactPoint rc;
    rc.element = k;
    rc.body = body;
    rc.geom = g;
    rc.segment_parameter = t;
    rc.position = cp.position;
    rc.normal = n_lab;
    rc.separation = cp.separation;
    rc.normal_force = fn;
    rc.force_on_rod = f_rod;
    rc.sticking = sticking;
    contacts_.push_back(rc);
  }

  RodContactParameters params_;
  std::vector<rigid::BodyId> excluded_;
  std::vector<Vec3> element_lo_, element_hi_;
  std::vector<RodContactPoint> contacts_, previous_contacts_;
  contact::SegmentCapsule capsule_;
  contact::ContactSet set_;
  contact::NarrowPhaseScratch scratch_;
  std::vector<Anchor> anchors_;  ///< kAnchorSlots per element
  struct AnchorUndo {
    Anchor* anchor;
    Anchor before;
  };
  std::vector<AnchorUndo> undo_;  ///< anchors changed by the last apply(), for restore()
  std::uint64_t pass_ = 1;       ///< apply() count (+1), for the anchors' liveness
  int narrow_calls_ = 0, previous_narrow_calls_ = 0;
  double max_penetration_ = 0, previous_max_penetration_ = 0;
};

}  // namespace manisoft::interaction
