// RigidWorld: rigid bodies with contact and Coulomb friction, stepped at the rod's timestep.
// Broad phase: FCL's DynamicAABBTreeCollisionManager over fattened AABBs (re-queried only when a
// fat box had to move). Narrow phase: narrow_phase.hpp, re-run for a pair only when its bodies have
// moved by more than half the contact margin since the last run; in between, the persistent
// manifolds (contact_manifold.hpp) extrapolate their separations. Solver: contact_solver.hpp.
// Islands of touching bodies that stay still for `time_to_sleep` are put to sleep (skipped) and
// wake when a force is applied, a velocity or pose is set, or a moving body touches them.
// Step order (symplectic Euler): contacts -> prepare -> v += h M^-1 f -> warm start -> solve ->
// x += h v, q += h/2 w q -> relax -> restitution -> store.
// Determinism: everything is iterated in body/geometry index order or in the order of the pairs'
// keys (the solver sorts its active manifolds; the manifold list keeps each pair in a slot).
// Allocation: after the first steps (buffers grown to their working size) step() allocates only
// when the set of overlapping pairs grows beyond its previous maximum (the narrow phase works in
// fixed-size buffers; query_capsule allocates only on first use).
// Rollback: step() records what it changes (begin_step) and puts it back (undo_step) when a
// body's state turns non-finite; save() / restore() snapshot the whole world at any time.
//
// Length: the world runs the step's stages above in order and keeps the bodies' bookkeeping that
// every stage reads (sleep, rollback, snapshots); the narrow phase, the manifolds and the solver
// live in contact/ (longer than the project's usual 600 lines for that reason).
#pragma once

#include "manisoft/contact/contact_solver.hpp"
#include "manisoft/contact/mixing.hpp"
#include "manisoft/contact/narrow_phase.hpp"
#include "manisoft/contact/segment_capsule.hpp"
#include "manisoft/rigid/rigid_body.hpp"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>

#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace manisoft::rigid {

struct RigidWorldSettings {
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};
  double contact_margin{0.002};      ///< m: speculative contact distance (points reported up to it)
  double contact_hertz{0};           ///< soft contact stiffness; 0 = 0.125 / dt
  double contact_damping_ratio{10};  ///< Box2D v3's default (overdamped: no bounce from correction)
  double max_push_velocity{1.0};     ///< m/s: cap on penetration recovery speed
  int solve_iterations{2};
  int relax_iterations{1};
  double restitution_threshold{0.2};  ///< m/s: slower impacts are inelastic
  bool warm_start{true};
  bool enable_sleep{true};
  double sleep_linear_velocity{0.005};  ///< m/s
  double sleep_angular_velocity{0.05};  ///< rad/s
  double time_to_sleep{0.5};            ///< s
};

/// A contact of a query capsule (e.g. a rod element) with a body of the world.
struct CapsuleContact {
  BodyId body{0};
  std::uint32_t geom{0};
  Eigen::Vector3d position{Eigen::Vector3d::Zero()};  ///< world, between the surfaces
  Eigen::Vector3d normal{Eigen::Vector3d::UnitZ()};   ///< unit, from the capsule into the body
  double separation{0};                               ///< < 0: penetration depth
  double segment_parameter{0};  ///< where along p0 -> p1 (0..1) the contact lies
};

/// One collision geometry: a primitive attached to a body (a compound has several).
struct RigidGeom {
  BodyId body{0};
  contact::Pose local;  ///< relative to the body's centre-of-mass frame
  contact::Vec3 surface_velocity{contact::Vec3::Zero()};  ///< of the geometry relative to its body, body frame (a moving finger)
  contact::CollisionShape shape;
  contact::Vec3 fat_lo{contact::Vec3::Zero()}, fat_hi{contact::Vec3::Zero()};
};

namespace detail {

/// An FCL collision object whose broad-phase AABB we set ourselves (fattened by a margin).
class FatCollisionObject : public fcl::CollisionObjectd {
 public:
  using fcl::CollisionObjectd::CollisionObjectd;
  void set_aabb(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    aabb.min_ = lo;
    aabb.max_ = hi;
  }
};

}  // namespace detail

class RigidWorld {
 public:
  using Vec3 = Eigen::Vector3d;
  using Mat3 = Eigen::Matrix3d;
  using Quat = Eigen::Quaterniond;

  explicit RigidWorld(RigidWorldSettings settings = {}) : settings_(std::move(settings)) {
    if (!settings_.gravity.allFinite()) ::manisoft::detail::fail("RigidWorldSettings::gravity must be finite");
    ::manisoft::detail::require_positive("RigidWorldSettings::contact_margin", settings_.contact_margin);
    ::manisoft::detail::require_non_negative("RigidWorldSettings::contact_hertz", settings_.contact_hertz);
    ::manisoft::detail::require_non_negative("RigidWorldSettings::contact_damping_ratio", settings_.contact_damping_ratio);
    ::manisoft::detail::require_positive("RigidWorldSettings::max_push_velocity", settings_.max_push_velocity);
    if (settings_.solve_iterations < 1 || settings_.relax_iterations < 0) {
      ::manisoft::detail::fail("RigidWorldSettings: solve_iterations = ", settings_.solve_iterations,
                               " must be >= 1 and relax_iterations = ", settings_.relax_iterations, " >= 0");
    }
    manager_ = std::make_unique<fcl::DynamicAABBTreeCollisionManagerd>();
  }

  // Movable (builders return worlds by value; the FCL objects live on the heap, so the broad
  // phase's pointers stay valid), not copyable (the FCL objects are owned once).
  RigidWorld(RigidWorld&&) noexcept = default;
  RigidWorld& operator=(RigidWorld&&) noexcept = default;
  RigidWorld(const RigidWorld&) = delete;
  RigidWorld& operator=(const RigidWorld&) = delete;

  // ---- building -------------------------------------------------------------------------------

  /// Adds a body; returns its id (0, 1, 2, ... in order of addition).
  BodyId add_body(const RigidBodyDesc& desc) {
    const auto id = static_cast<BodyId>(models_.size());
    RigidBodyModel model = make_body_model(desc, id);
    RigidBodyState state;
    state.orientation = desc.orientation.normalized();
    state.rotation = state.orientation.toRotationMatrix();
    state.position = desc.position + state.rotation * model.center_of_mass;
    if (!desc.is_static) {
      state.linear_velocity = desc.linear_velocity;
      state.angular_velocity = desc.angular_velocity;
    }
    model.first_geom = static_cast<std::uint32_t>(geoms_.size());
    auto add_geom = [&](const geometry::PrimitiveShape<double>& prim, const Vec3& pos, const Quat& q) {
      RigidGeom g;
      g.body = id;
      Vec3 mesh_origin = Vec3::Zero();
      g.local.rotation = q.normalized().toRotationMatrix();
      g.local.translation = pos - model.center_of_mass;
      if (std::holds_alternative<geometry::ConvexMesh<double>>(prim)) {
        // Mesh vertices are re-centred on the body's centre of mass: the geom sits at the COM.
        mesh_origin = model.center_of_mass - pos;  // in the part frame when q = identity
        mesh_origin = g.local.rotation.transpose() * (model.center_of_mass - pos);
        g.local.translation = Vec3::Zero();
      }
      g.shape = contact::make_collision_shape(prim, mesh_origin);
      model.bounding_radius = std::max(model.bounding_radius, g.local.translation.norm() + g.shape.bounding_radius);
      geoms_.push_back(std::move(g));
    };
    std::visit(
        [&](const auto& s) {
          using S = std::decay_t<decltype(s)>;
          if constexpr (std::is_same_v<S, geometry::Compound<double>>) {
            for (const auto& part : s.parts) add_geom(part.shape, part.position, part.orientation);
          } else {
            add_geom(geometry::PrimitiveShape<double>(s), Vec3::Zero(), Quat::Identity());
          }
        },
        desc.shape);
    model.geom_count = static_cast<std::uint32_t>(geoms_.size()) - model.first_geom;
    models_.push_back(std::move(model));
    states_.push_back(state);
    for (std::uint32_t g = models_.back().first_geom; g < geoms_.size(); ++g) {
      auto obj = std::make_unique<detail::FatCollisionObject>(geoms_[g].shape.fcl_geometry);
      obj->setUserData(reinterpret_cast<void*>(static_cast<std::uintptr_t>(g) + 1));  // 0 = query object
      fcl_objects_.push_back(std::move(obj));
      refresh_fat_bounds(g, true);
      manager_->registerObject(fcl_objects_[g].get());
    }
    broadphase_dirty_ = true;
    moved_flag_.resize(geoms_.size(), 0);
    moved_.reserve(geoms_.size());
    // Per-body step buffers at their working size now, so no step allocates for them; candidate
    // pairs get room for every pair of geoms (at most 16 per geom).
    const std::size_t bodies = models_.size(), g = geoms_.size();
    record_.states.reserve(bodies);
    record_.boxes.reserve(g);
    solver_bodies_.reserve(bodies);
    parent_.reserve(bodies);
    island_min_time_.reserve(bodies);
    pairs_.reserve(std::min(g * (g - 1) / 2, 16 * g));
    old_pairs_.reserve(pairs_.capacity());
    keys_.reserve(pairs_.capacity());
    manifolds_.reserve(pairs_.capacity());
    dropped_.reserve(pairs_.capacity());
    record_.ops.reserve(2 * pairs_.capacity());  // a step removes at most the old pairs, adds at most the new
    record_.removed.reserve(pairs_.capacity());
    active_.reserve(pairs_.capacity());
    record_.manifolds.reserve(2 * pairs_.capacity());
    return id;
  }

  // ---- stepping -------------------------------------------------------------------------------

  /// Advances the world by `dt` seconds. Throws manisoft::Diverged, with the world put back to
  /// its state before the step (bodies, contact caches, counters), if a body's state becomes
  /// non-finite; the loads queued for the failed step are dropped.
  void step(double dt) {
    begin_step();
    try {
      advance(dt);
    } catch (...) {
      undo_step();
      clear_external_loads();
      throw;
    }
  }

  /// Starts recording what the next advance() changes (body states, the manifolds it touches,
  /// the broad-phase boxes it moves, counters), so undo_step() can put the world back: the cheap
  /// per-step rollback (what a step touches, not the whole world) that step() and the arm world use.
  void begin_step() {
    record_.states = states_;
    record_.ops.clear();
    record_.removed.clear();
    record_.manifolds.clear();
    record_.boxes.clear();
    record_.broadphase_dirty = broadphase_dirty_;
    record_.time = time_;
    record_.step_count = step_count_;
    recording_ = true;
  }
  /// Undoes everything since begin_step().
  void undo_step() {
    if (!recording_) ::manisoft::detail::fail("RigidWorld::undo_step without begin_step");
    states_ = record_.states;
    for (auto it = record_.manifolds.rbegin(); it != record_.manifolds.rend(); ++it) manifolds_[it->first] = it->second.manifold();
    auto removed = record_.removed.rbegin();
    for (auto it = record_.ops.rbegin(); it != record_.ops.rend(); ++it) {
      if (!it->removed) {  // an added pair: it is the last slot
        manifolds_.pop_back();
        keys_.pop_back();
        continue;
      }
      const contact::ContactManifold m = (removed++)->manifold();
      if (it->slot == manifolds_.size()) {  // the last slot was removed
        manifolds_.push_back(m);
        keys_.push_back(m.key());
      } else {  // the last slot had moved into the removed one
        manifolds_.push_back(manifolds_[it->slot]);
        keys_.push_back(keys_[it->slot]);
        manifolds_[it->slot] = m;
        keys_[it->slot] = m.key();
      }
    }
    for (auto it = record_.boxes.rbegin(); it != record_.boxes.rend(); ++it) {
      auto& geom = geoms_[it->geom];
      geom.fat_lo = it->lo;
      geom.fat_hi = it->hi;
      fcl_objects_[it->geom]->set_aabb(geom.fat_lo, geom.fat_hi);
      manager_->update(fcl_objects_[it->geom].get());
    }
    broadphase_dirty_ = record_.broadphase_dirty;
    time_ = record_.time;
    step_count_ = record_.step_count;
    recording_ = false;
  }

  /// One step. Without begin_step() a failure leaves the world partly advanced; with it,
  /// undo_step() restores it (step() does both).
  void advance(double dt) {
    if (!std::isfinite(dt) || !(dt > 0)) ::manisoft::detail::fail("RigidWorld::step: dt = ", dt, " must be finite and > 0");
    contact::ContactSolverSettings cs;
    cs.h = dt;
    const double hertz = settings_.contact_hertz > 0 ? std::min(settings_.contact_hertz, 0.25 / dt) : 0.125 / dt;
    cs.soft = contact::SoftParameters::make(hertz, settings_.contact_damping_ratio, dt);
    cs.max_push_velocity = settings_.max_push_velocity;
    cs.restitution_threshold = settings_.restitution_threshold;
    cs.warm_start = settings_.warm_start;

    update_broadphase();
    update_narrowphase();
    update_islands();

    // Solver bodies: awake dynamic bodies move; static and sleeping ones are immovable.
    solver_bodies_.resize(models_.size());
    for (std::size_t i = 0; i < models_.size(); ++i) {
      auto& b = solver_bodies_[i];
      const auto& m = models_[i];
      const auto& s = states_[i];
      b.v = s.linear_velocity;
      b.w = s.angular_velocity;
      if (m.is_static || !s.awake) {
        b.inv_mass = 0;
        b.inv_inertia.setZero();
      } else {
        b.inv_mass = m.inverse_mass;
        b.inv_inertia = s.rotation * m.inverse_inertia * s.rotation.transpose();
      }
    }
    // The solver's passes visit only the active manifolds (a nested stack has hundreds of pairs,
    // few of them touching and moving), in the order of their pair keys.
    active_.clear();
    if (active_.capacity() < manifolds_.size()) active_.reserve(manifolds_.capacity());
    for (std::size_t i = 0; i < manifolds_.size(); ++i) {
      auto& m = manifolds_[i];
      if (m.count == 0 || !(is_moving(m.body_a) || is_moving(m.body_b))) continue;
      record_manifold(i);  // its impulses and friction drift change below
      m.surface_velocity = states_[m.body_b].rotation * geoms_[m.geom_b].surface_velocity -
                           states_[m.body_a].rotation * geoms_[m.geom_a].surface_velocity;
      active_.push_back(&m);
    }
    std::sort(active_.begin(), active_.end(), [](const contact::ContactManifold* a, const contact::ContactManifold* b) { return a->key() < b->key(); });
    contact::prepare_contacts(active_, states_, solver_bodies_);
    integrate_velocities(dt);
    if (settings_.warm_start) contact::warm_start_contacts(active_, solver_bodies_);
    for (int it = 0; it < settings_.solve_iterations; ++it) contact::solve_contacts(active_, solver_bodies_, cs, true);
    integrate_positions(dt);
    contact::update_after_position_integration(active_, solver_bodies_, cs);
    for (int it = 0; it < settings_.relax_iterations; ++it) contact::solve_contacts(active_, solver_bodies_, cs, false);
    contact::apply_restitution(active_, solver_bodies_, cs);
    contact::store_impulses(active_, cs);
    finish_step(dt);
  }

  // ---- snapshot -------------------------------------------------------------------------------

  /// Everything a step changes: body states, what the contact manifolds carry between steps
  /// (cached points, warm-start impulses, friction drift), broad-phase boxes, counters. Reused
  /// between steps: saving into the same snapshot allocates only when the number of manifolds grew.
  struct Snapshot {
    std::vector<RigidBodyState> states;
    std::vector<contact::ManifoldMemory> manifolds;
    std::vector<Vec3> fat_lo, fat_hi;
    bool broadphase_dirty{true};
    double time{0};
    std::uint64_t step_count{0};
  };
  void save(Snapshot& out) const {
    out.states = states_;
    out.manifolds.resize(manifolds_.size());
    for (std::size_t i = 0; i < manifolds_.size(); ++i) out.manifolds[i] = contact::ManifoldMemory::of(manifolds_[i]);
    out.fat_lo.resize(geoms_.size());
    out.fat_hi.resize(geoms_.size());
    for (std::size_t g = 0; g < geoms_.size(); ++g) {
      out.fat_lo[g] = geoms_[g].fat_lo;
      out.fat_hi[g] = geoms_[g].fat_hi;
    }
    out.broadphase_dirty = broadphase_dirty_;
    out.time = time_;
    out.step_count = step_count_;
  }
  /// Puts the world back to a snapshot taken of it (same bodies).
  void restore(const Snapshot& in) {
    if (in.states.size() != states_.size() || in.fat_lo.size() != geoms_.size())
      ::manisoft::detail::fail("RigidWorld::restore: the snapshot has ", in.states.size(), " bodies, the world ", states_.size());
    states_ = in.states;
    manifolds_.resize(in.manifolds.size());
    keys_.resize(in.manifolds.size());
    for (std::size_t i = 0; i < manifolds_.size(); ++i) {
      manifolds_[i] = in.manifolds[i].manifold();
      keys_[i] = manifolds_[i].key();
    }
    for (std::uint32_t g = 0; g < geoms_.size(); ++g) {
      if (geoms_[g].fat_lo == in.fat_lo[g] && geoms_[g].fat_hi == in.fat_hi[g]) continue;
      geoms_[g].fat_lo = in.fat_lo[g];
      geoms_[g].fat_hi = in.fat_hi[g];
      fcl_objects_[g]->set_aabb(geoms_[g].fat_lo, geoms_[g].fat_hi);
      manager_->update(fcl_objects_[g].get());
    }
    broadphase_dirty_ = in.broadphase_dirty;
    time_ = in.time;
    step_count_ = in.step_count;
  }

  // ---- queries --------------------------------------------------------------------------------

  std::size_t body_count() const { return models_.size(); }
  const RigidBodyModel& model(BodyId id) const { return models_.at(id); }
  const RigidBodyState& state(BodyId id) const { return states_.at(id); }
  const RigidWorldSettings& settings() const { return settings_; }
  double time() const { return time_; }
  std::uint64_t step_count() const { return step_count_; }

  /// Position of the body's shape frame origin (as given in RigidBodyDesc::position).
  Vec3 position(BodyId id) const {
    const auto& s = states_.at(id);
    return s.position - s.rotation * models_[id].center_of_mass;
  }
  Vec3 center_of_mass(BodyId id) const { return states_.at(id).position; }
  Quat orientation(BodyId id) const { return states_.at(id).orientation; }
  Vec3 linear_velocity(BodyId id) const { return states_.at(id).linear_velocity; }
  Vec3 angular_velocity(BodyId id) const { return states_.at(id).angular_velocity; }
  bool is_awake(BodyId id) const { return states_.at(id).awake; }
  /// Velocity of the body's material point at world position p.
  Vec3 velocity_at_point(BodyId id, const Vec3& p) const {
    const auto& s = states_.at(id);
    return s.linear_velocity + s.angular_velocity.cross(p - s.position);
  }
  /// Kinetic plus gravitational potential energy of all dynamic bodies (J).
  double mechanical_energy() const {
    double e = 0;
    for (std::size_t i = 0; i < models_.size(); ++i) {
      if (models_[i].is_static) continue;
      const auto& s = states_[i];
      const Vec3 wb = s.rotation.transpose() * s.angular_velocity;
      e += 0.5 * models_[i].mass * s.linear_velocity.squaredNorm() + 0.5 * wb.dot(models_[i].inertia * wb) -
           models_[i].mass * settings_.gravity.dot(s.position);
    }
    return e;
  }
  /// One manifold per pair of overlapping fat boxes, in no particular order (update_broadphase).
  const std::vector<contact::ContactManifold>& manifolds() const { return manifolds_; }
  const std::vector<RigidGeom>& geoms() const { return geoms_; }
  /// Number of contact points with separation <= 0 (touching) this step.
  std::size_t touching_point_count() const {
    std::size_t n = 0;
    for (const auto& m : manifolds_) for (int k = 0; k < m.count; ++k) n += m.points[static_cast<std::size_t>(k)].separation <= 0;
    return n;
  }

  /// Contacts of the capsule p0-p1 of radius `radius` (e.g. a rod element, moving every step)
  /// with every body's geometry, reported up to separation `margin`. `out` is cleared and filled
  /// in (body, geometry) order; its capacity is reused.
  void query_capsule(const Vec3& p0, const Vec3& p1, double radius, double margin, std::vector<CapsuleContact>& out) {
    out.clear();
    if (!p0.allFinite() || !p1.allFinite() || !std::isfinite(radius) || radius < 0 || !std::isfinite(margin) || margin < 0) {
      ::manisoft::detail::fail("RigidWorld::query_capsule: end points, radius = ", radius, " and margin = ", margin,
                               " must be finite (radius, margin >= 0)");
    }
    query_capsule_.set(p0, p1, radius, contact::detail::any_perpendicular(p1 - p0));
    if (!query_object_) {
      query_object_ = std::make_unique<detail::FatCollisionObject>(query_capsule_.fcl_capsule());
      query_object_->setUserData(nullptr);  // FCL leaves user data uninitialised
    }
    const Vec3 pad = Vec3::Constant(radius + margin);
    query_object_->set_aabb(p0.cwiseMin(p1) - pad, p0.cwiseMax(p1) + pad);
    query_candidates_.clear();
    manager_->collide(query_object_.get(), &query_candidates_, &collect_query);
    std::sort(query_candidates_.begin(), query_candidates_.end());
    for (const auto g : query_candidates_) {
      const auto& geom = geoms_[g];
      const contact::Pose gp = geom_pose(g);
      if (!contact::collide(query_capsule_.shape(), query_capsule_.pose(), geom.shape, gp, margin, contact_scratch_, scratch_)) continue;
      for (int k = 0; k < contact_scratch_.count; ++k) {
        const auto& cp = contact_scratch_.points[static_cast<std::size_t>(k)];
        CapsuleContact c;
        c.body = geom.body;
        c.geom = g;
        c.position = cp.position;
        c.normal = contact_scratch_.normal;
        c.separation = cp.separation;
        c.segment_parameter = query_capsule_.segment_parameter(cp.position);
        out.push_back(c);
      }
    }
  }

  // ---- external actions (rod contact, gripper, spring coupling) --------------------------------

  /// Adds a force (N, world) at the centre of mass for the next step. Wakes the body.
  void add_force(BodyId id, const Vec3& force) { add_force_and_torque(id, force, Vec3::Zero()); }
  /// Adds a torque (N m, world) for the next step. Wakes the body.
  void add_torque(BodyId id, const Vec3& torque) { add_force_and_torque(id, Vec3::Zero(), torque); }
  /// Adds a force (N, world) applied at world point p for the next step: f and (p - x_com) x f.
  void add_force_at_point(BodyId id, const Vec3& force, const Vec3& point) {
    if (!point.allFinite()) ::manisoft::detail::fail("rigid body ", id, ": force application point is not finite");
    add_force_and_torque(id, force, (point - states_.at(id).position).cross(force));
  }
  void add_force_and_torque(BodyId id, const Vec3& force, const Vec3& torque) {
    check_id(id);
    if (!force.allFinite() || !torque.allFinite()) {
      ::manisoft::detail::fail("rigid body ", id, describe(id), ": external force (", force.transpose(), ") or torque (",
                               torque.transpose(), ") is not finite");
    }
    if (models_[id].is_static) return;
    auto& s = states_[id];
    s.force += force;
    s.torque += torque;
    if (force.squaredNorm() > 0 || torque.squaredNorm() > 0) s.sleep_time = 0;
  }
  /// Drops every force and torque added for the next step (e.g. after a coupled step failed).
  void clear_external_loads() {
    for (auto& s : states_) {
      s.force.setZero();
      s.torque.setZero();
    }
  }
  void set_velocity(BodyId id, const Vec3& linear, const Vec3& angular) {
    check_id(id);
    if (!linear.allFinite() || !angular.allFinite()) ::manisoft::detail::fail("rigid body ", id, describe(id), ": velocity is not finite");
    if (models_[id].is_static) ::manisoft::detail::fail("rigid body ", id, describe(id), " is static: its velocity cannot be set");
    states_[id].linear_velocity = linear;
    states_[id].angular_velocity = angular;
    states_[id].sleep_time = 0;
  }
  /// Teleports a body (shape-frame origin and orientation). Its cached contacts are re-detected.
  void set_pose(BodyId id, const Vec3& position, const Quat& orientation) {
    check_id(id);
    if (!position.allFinite() || !orientation.coeffs().allFinite() || orientation.norm() < 1e-9) {
      ::manisoft::detail::fail("rigid body ", id, describe(id), ": pose is not finite");
    }
    auto& s = states_[id];
    s.orientation = orientation.normalized();
    s.rotation = s.orientation.toRotationMatrix();
    s.position = position + s.rotation * models_[id].center_of_mass;
    s.travel += 1e3;  // forces re-detection of every pair of this body
    s.sleep_time = 0;
    for (std::uint32_t g = models_[id].first_geom; g < models_[id].first_geom + models_[id].geom_count; ++g) {
      refresh_fat_bounds(g, true);
      manager_->update(fcl_objects_[g].get());
    }
    broadphase_dirty_ = true;
  }

  /// Contact left out between some geometries of one body and another body (set_excluded_contact).
  struct ExcludedContact {
    std::uint32_t first_geom{0}, geom_count{0};  ///< geometries [first_geom, first_geom + geom_count) of one body
    BodyId body{0};                              ///< ... and every geometry of this (other) body
  };
  /// Leaves out contact between some geometries of one body and another body (a gripper and
  /// the object its weld holds) until cleared (nullopt) or replaced: their manifolds
  /// are kept empty, and re-detected from scratch once the exclusion ends. A setting, not state:
  /// whoever sets it sets it again after a restore (a manifold's memory says whether it was
  /// excluded, so a replay gives the same contacts).
  void set_excluded_contact(std::optional<ExcludedContact> e) {
    if (e) {
      check_id(e->body);
      if (e->geom_count == 0 || std::size_t(e->first_geom) + e->geom_count > geoms_.size() ||
          geoms_[e->first_geom].body != geoms_[e->first_geom + e->geom_count - 1].body || geoms_[e->first_geom].body == e->body) {
        ::manisoft::detail::fail("excluded contact: geometries [", e->first_geom, ", ", std::size_t(e->first_geom) + e->geom_count,
                                 ") are not geometries of one body other than body ", e->body, " (", geoms_.size(), " geometries)");
      }
    }
    excluded_ = e;
  }
  std::optional<ExcludedContact> excluded_contact() const { return excluded_; }

  /// Moves geometry g within its body (a gripper's finger): its translation relative to the
  /// body's centre-of-mass frame and the velocity it moves at relative to the body (body frame;
  /// the contact solver sees its surface move, so a finger pushes what it closes on at its own
  /// speed). The body's mass properties stay as built and the geometry must stay within the
  /// body's bounding radius. With `redetect`, its cached contacts are re-detected at the next step
  /// (without: the caches already belong to this placement, as after a restore).
  void set_geom_translation(std::uint32_t g, const Vec3& local, const Vec3& velocity, bool redetect = true) {
    if (g >= geoms_.size()) ::manisoft::detail::fail("geometry id ", g, " out of range (", geoms_.size(), " geometries)");
    auto& geom = geoms_[g];
    const auto& model = models_[geom.body];
    if (!local.allFinite() || !velocity.allFinite() || local.norm() + geom.shape.bounding_radius > model.bounding_radius + 1e-12) {
      ::manisoft::detail::fail("geometry ", g, " of rigid body ", geom.body, describe(geom.body), ": translation (", local.transpose(),
                               ") or velocity (", velocity.transpose(), ") is not finite or the translation leaves the body's bounding radius ",
                               model.bounding_radius, " m");
    }
    geom.local.translation = local;
    geom.surface_velocity = velocity;
    if (!redetect) return;
    if (!model.is_static) states_[geom.body].sleep_time = 0;
    for (std::size_t i = 0; i < manifolds_.size(); ++i) {
      auto& m = manifolds_[i];
      if (m.fresh || (m.geom_a != g && m.geom_b != g)) continue;
      record_manifold(i);
      m.fresh = true;
    }
  }

  /// World placement of geometry g.
  contact::Pose geom_pose(std::uint32_t g) const {
    const auto& geom = geoms_[g];
    const auto& s = states_[geom.body];
    contact::Pose p;
    p.rotation = s.rotation * geom.local.rotation;
    p.translation = s.position + s.rotation * geom.local.translation;
    return p;
  }

 private:
  /// Broad-phase callback: keeps the pairs that can touch (two bodies, not both static). A
  /// compound's own pieces overlap each other and would otherwise be most of the list.
  static bool collect_pair(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
    auto* world = static_cast<RigidWorld*>(data);
    auto a = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(o1->getUserData()) - 1);
    auto b = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(o2->getUserData()) - 1);
    const auto& ga = world->geoms_[a];
    const auto& gb = world->geoms_[b];
    if (ga.body == gb.body || (world->models_[ga.body].is_static && world->models_[gb.body].is_static)) return false;
    // FCL keeps a leaf's box when a smaller one is set (after a teleport, undo or restore): the
    // pair is kept only if our own boxes overlap.
    if (!((ga.fat_lo.array() <= gb.fat_hi.array()).all() && (gb.fat_lo.array() <= ga.fat_hi.array()).all())) return false;
    if (a > b) std::swap(a, b);
    world->pairs_.push_back((std::uint64_t(a) << 32) | b);
    return false;
  }
  /// Broad-phase callback of one moved geom's query: as collect_pair; a pair of two moved geoms is
  /// found by both queries and kept from the lower one's.
  static bool collect_moved_pair(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
    auto* world = static_cast<RigidWorld*>(data);
    const auto a = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(o1->getUserData()) - 1);
    const auto b = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(o2->getUserData()) - 1);
    const auto other = a == world->query_geom_ ? b : a;
    if (world->moved_flag_[other] && other < world->query_geom_) return false;
    return collect_pair(o1, o2, data);
  }
  static bool collect_query(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
    auto* out = static_cast<std::vector<std::uint32_t>*>(data);
    // One of the two is the query object (user data 0); the other carries geometry index + 1.
    const auto tag = reinterpret_cast<std::uintptr_t>(o1->getUserData()) + reinterpret_cast<std::uintptr_t>(o2->getUserData());
    if (tag > 0) out->push_back(static_cast<std::uint32_t>(tag - 1));
    return false;
  }

  std::string describe(BodyId id) const {
    return models_[id].name.empty() ? std::string() : " ('" + models_[id].name + "')";
  }
  void check_id(BodyId id) const {
    if (id >= models_.size()) ::manisoft::detail::fail("rigid body id ", id, " out of range (", models_.size(), " bodies)");
  }
  static bool is_round(contact::ShapeKind k) {
    return k == contact::ShapeKind::sphere || k == contact::ShapeKind::capsule || k == contact::ShapeKind::cylinder;
  }
  bool is_moving(BodyId id) const { return !models_[id].is_static && states_[id].awake; }

  bool excluded(const contact::ContactManifold& m) const {
    if (!excluded_) return false;
    const auto in_range = [&](std::uint32_t g) { return g - excluded_->first_geom < excluded_->geom_count; };
    return (in_range(m.geom_a) && m.body_b == excluded_->body) || (in_range(m.geom_b) && m.body_a == excluded_->body);
  }

  /// Keeps manifold i's memory from before this step's changes to it (slot i after the list's changes).
  void record_manifold(std::size_t i) {
    if (recording_) record_.manifolds.emplace_back(static_cast<std::uint32_t>(i), contact::ManifoldMemory::of(manifolds_[i]));
  }

  /// Recomputes the fat AABB of geometry g if its margin-inflated bounds left it (or if forced).
  bool refresh_fat_bounds(std::uint32_t g, bool force) {
    auto& geom = geoms_[g];
    Vec3 lo, hi;
    geom.shape.bounds(geom_pose(g), lo, hi);
    const Vec3 m = Vec3::Constant(settings_.contact_margin);
    lo -= m;
    hi += m;
    if (!force && (lo.array() >= geom.fat_lo.array()).all() && (hi.array() <= geom.fat_hi.array()).all()) return false;
    const Vec3 slack = Vec3::Constant(models_[geom.body].is_static ? 0.0 : 2.0 * settings_.contact_margin + 0.002);
    if (recording_) record_.boxes.push_back({g, geom.fat_lo, geom.fat_hi});
    geom.fat_lo = lo - slack;
    geom.fat_hi = hi + slack;
    fcl_objects_[g]->set_aabb(geom.fat_lo, geom.fat_hi);
    return true;
  }

  /// The manifold list holds one manifold per overlapping pair of fat boxes (geoms of two bodies,
  /// not both static), each in a fixed slot until its pair separates: a removed pair's slot takes
  /// the last manifold, new pairs are appended. After a change the broad phase cannot follow (a new
  /// body, a teleport, a restored snapshot marked dirty) the whole tree is collided with itself;
  /// otherwise only the geoms whose fat box moved are queried, and only their pairs can change.
  void update_broadphase() {
    moved_.clear();
    for (std::uint32_t g = 0; g < geoms_.size(); ++g) {
      if (!is_moving(geoms_[g].body)) continue;
      if (refresh_fat_bounds(g, false)) {
        manager_->update(fcl_objects_[g].get());
        moved_.push_back(g);
      }
    }
    if (!broadphase_dirty_ && moved_.empty()) return;
    // pairs_: the overlapping pairs that this update decides; old_pairs_: the manifolds it may drop.
    pairs_.clear();
    old_pairs_.clear();
    if (broadphase_dirty_) {
      manager_->collide(this, &collect_pair);
      for (std::uint32_t i = 0; i < keys_.size(); ++i) old_pairs_.push_back({keys_[i], i});
    } else {
      for (const auto g : moved_) moved_flag_[g] = 1;
      for (std::uint32_t i = 0; i < keys_.size(); ++i) {
        if (moved_flag_[keys_[i] >> 32] || moved_flag_[keys_[i] & 0xffffffffu]) old_pairs_.push_back({keys_[i], i});
      }
      for (const auto g : moved_) {
        query_geom_ = g;
        manager_->collide(fcl_objects_[g].get(), this, &collect_moved_pair);
      }
      for (const auto g : moved_) moved_flag_[g] = 0;
    }
    broadphase_dirty_ = false;
    std::sort(pairs_.begin(), pairs_.end());
    std::sort(old_pairs_.begin(), old_pairs_.end());
    // Drop the manifolds whose pair is gone (highest slot first: the last slot, which takes the
    // place of a removed one, is then never one still to remove).
    dropped_.clear();
    std::size_t j = 0;
    for (const auto& [key, slot] : old_pairs_) {
      while (j < pairs_.size() && pairs_[j] < key) ++j;
      if (j == pairs_.size() || pairs_[j] != key) dropped_.push_back(slot);
    }
    std::sort(dropped_.begin(), dropped_.end(), std::greater<>());
    for (const auto slot : dropped_) {
      if (recording_) {
        record_.ops.push_back({slot, true});
        record_.removed.push_back(contact::ManifoldMemory::of(manifolds_[slot]));
      }
      if (slot + 1 < manifolds_.size()) {
        manifolds_[slot] = manifolds_.back();
        keys_[slot] = keys_.back();
      }
      manifolds_.pop_back();
      keys_.pop_back();
    }
    // Append the new pairs, in key order.
    std::size_t o = 0;
    for (const auto key : pairs_) {
      while (o < old_pairs_.size() && old_pairs_[o].first < key) ++o;
      if (o < old_pairs_.size() && old_pairs_[o].first == key) continue;
      const auto ga = static_cast<std::uint32_t>(key >> 32), gb = static_cast<std::uint32_t>(key & 0xffffffffu);
      const BodyId ba = geoms_[ga].body, bb = geoms_[gb].body;
      contact::ContactManifold m;
      m.geom_a = ga;
      m.geom_b = gb;
      m.body_a = ba;
      m.body_b = bb;
      m.friction = contact::mix_friction(models_[ba].friction, models_[bb].friction);
      m.restitution = contact::mix_restitution(models_[ba].restitution, models_[bb].restitution);
      m.rolling_resistance = contact::mix_rolling_resistance(models_[ba].rolling_resistance, models_[bb].rolling_resistance);
      m.fresh = true;
      if (recording_) record_.ops.push_back({static_cast<std::uint32_t>(manifolds_.size()), false});
      manifolds_.push_back(m);
      keys_.push_back(key);
    }
  }

  void update_narrowphase() {
    const double redetect = 0.5 * settings_.contact_margin;
    for (std::size_t i = 0; i < manifolds_.size(); ++i) {
      auto& m = manifolds_[i];
      if (excluded(m)) {
        if (m.count > 0 || !m.fresh) {
          record_manifold(i);
          m.count = 0;
          m.patch = {};
          m.fresh = true;  // re-detected once the exclusion ends
        }
        continue;
      }
      const auto& sa = states_[m.body_a];
      const auto& sb = states_[m.body_b];
      // Analytic pairs with a rounded shape (sphere, capsule, cylinder: a cylinder on its cap
      // too), and pairs whose last contact was a rolling one, are re-evaluated every step while a
      // body moves: a rolling body's contact is not a material point (the cached extrapolation
      // would let it sink and would move the lever arm). A cylinder rocking on its cap keeps four
      // of its rim points; cached, the rim between them sank as the tilt turned and was pushed
      // back out at the next detection, a lift that fed the rocking. Face contacts of polyhedra
      // (SAT) use the cache; bodies at rest sleep.
      const auto ka = geoms_[m.geom_a].shape.kind, kb = geoms_[m.geom_b].shape.kind;
      const bool analytic_round = (is_round(ka) && (is_round(kb) || kb == contact::ShapeKind::box)) ||
                                  (is_round(kb) && ka == contact::ShapeKind::box);
      const bool moving = is_moving(m.body_a) || is_moving(m.body_b);
      if (!m.fresh && !((analytic_round || m.rolling) && moving) && (sa.travel - m.travel_a) + (sb.travel - m.travel_b) <= redetect) continue;
      record_manifold(i);
      m.fresh = false;
      m.travel_a = sa.travel;
      m.travel_b = sb.travel;
      auto& c = contact_scratch_;
      if (!contact::collide(geoms_[m.geom_a].shape, geom_pose(m.geom_a), geoms_[m.geom_b].shape, geom_pose(m.geom_b),
                            settings_.contact_margin, c, scratch_)) {
        c.clear();
      }
      rebuild_manifold(m, c);
    }
  }

  /// Replaces the points of m by the new contact set, matching them to cached points by
  /// proximity to carry impulses and friction drift over.
  void rebuild_manifold(contact::ContactManifold& m, const contact::ContactSet& c) {
    const auto& sa = states_[m.body_a];
    const auto& sb = states_[m.body_b];
    const Vec3 old_normal = (m.owner == contact::NormalOwner::shape_a ? sa.rotation : sb.rotation) * m.normal_local;
    std::array<Vec3, contact::kMaxContactPoints> old_pos;
    for (int k = 0; k < m.count; ++k) {
      const auto& p = m.points[static_cast<std::size_t>(k)];
      old_pos[static_cast<std::size_t>(k)] = 0.5 * (sa.position + sa.rotation * p.anchor_a + sb.position + sb.rotation * p.anchor_b);
    }
    const auto old_points = m.points;
    const int old_count = m.count;
    std::array<bool, contact::kMaxContactPoints> used{};
    const bool same_normal = old_count > 0 && old_normal.dot(c.normal) > 0.95;
    const double match2 = std::pow(std::max(settings_.contact_margin, 1e-3), 2);
    if (!same_normal) m.patch = {};  // a new contact (or a flipped normal): no friction history
    m.count = c.count;
    m.rolling = c.rolling;
    m.owner = c.normal_owner;
    m.normal_local = (c.normal_owner == contact::NormalOwner::shape_a ? sa.rotation : sb.rotation).transpose() * c.normal;
    for (int k = 0; k < c.count; ++k) {
      const auto& cp = c.points[static_cast<std::size_t>(k)];
      contact::ManifoldPoint p;
      p.anchor_a = sa.rotation.transpose() * (cp.position - sa.position);
      p.anchor_b = sb.rotation.transpose() * (cp.position - sb.position);
      p.base_separation = cp.separation;
      if (same_normal) {
        int best = -1;
        double best_d2 = match2;
        for (int j = 0; j < old_count; ++j) {
          if (used[static_cast<std::size_t>(j)]) continue;
          const double d2 = (old_pos[static_cast<std::size_t>(j)] - cp.position).squaredNorm();
          if (d2 < best_d2) { best_d2 = d2; best = j; }
        }
        if (best >= 0) {
          used[static_cast<std::size_t>(best)] = true;
          p.normal_impulse = old_points[static_cast<std::size_t>(best)].normal_impulse;
        }
      }
      m.points[static_cast<std::size_t>(k)] = p;
    }
  }

  /// Islands of bodies joined by contact manifolds; an island sleeps when all its bodies have been
  /// still for time_to_sleep (and wakes as soon as one has not).
  void update_islands() {
    const std::size_t n = models_.size();
    if (!settings_.enable_sleep) {
      for (auto& s : states_) s.awake = true;
      return;
    }
    parent_.resize(n);
    island_min_time_.resize(n);
    for (std::size_t i = 0; i < n; ++i) parent_[i] = static_cast<std::uint32_t>(i);
    auto find = [&](std::uint32_t i) {
      while (parent_[i] != i) { parent_[i] = parent_[parent_[i]]; i = parent_[i]; }
      return i;
    };
    for (const auto& m : manifolds_) {
      if (m.count == 0 || models_[m.body_a].is_static || models_[m.body_b].is_static) continue;
      const auto ra = find(m.body_a), rb = find(m.body_b);
      if (ra != rb) parent_[std::max(ra, rb)] = std::min(ra, rb);
    }
    for (std::size_t i = 0; i < n; ++i) island_min_time_[i] = INFINITY;
    for (std::size_t i = 0; i < n; ++i) {
      if (models_[i].is_static) continue;
      const auto r = find(static_cast<std::uint32_t>(i));
      island_min_time_[r] = std::min(island_min_time_[r], states_[i].sleep_time);
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (models_[i].is_static) continue;
      auto& s = states_[i];
      const bool awake = island_min_time_[find(static_cast<std::uint32_t>(i))] < settings_.time_to_sleep;
      if (!awake && s.awake) {
        s.linear_velocity.setZero();
        s.angular_velocity.setZero();
      }
      s.awake = awake;
    }
  }

  void integrate_velocities(double h) {
    for (std::size_t i = 0; i < models_.size(); ++i) {
      if (!is_moving(static_cast<BodyId>(i))) continue;
      const auto& m = models_[i];
      auto& s = states_[i];
      auto& b = solver_bodies_[i];
      b.v += h * (settings_.gravity + m.inverse_mass * s.force);
      // Angular: external torque explicitly, then the gyroscopic term implicitly in body axes,
      // one Newton step on f(w) = I (w - w0) + h w x I w = 0 (Catto, GDC 2015).
      Vec3 wb = s.rotation.transpose() * (b.w + h * (b.inv_inertia * s.torque));
      const Vec3 iw = m.inertia * wb;
      const Vec3 f = h * wb.cross(iw);
      if (h * wb.squaredNorm() > 1e-14) {  // negligible for bodies at rest
        Mat3 skew_w, skew_iw;
        skew_w << 0, -wb.z(), wb.y(), wb.z(), 0, -wb.x(), -wb.y(), wb.x(), 0;
        skew_iw << 0, -iw.z(), iw.y(), iw.z(), 0, -iw.x(), -iw.y(), iw.x(), 0;
        const Mat3 jac = m.inertia + h * (skew_w * m.inertia - skew_iw);
        wb -= jac.inverse() * f;  // closed-form 3x3 inverse
      }
      b.w = s.rotation * wb;
    }
  }

  void integrate_positions(double h) {
    for (std::size_t i = 0; i < models_.size(); ++i) {
      if (!is_moving(static_cast<BodyId>(i))) continue;
      auto& s = states_[i];
      const auto& b = solver_bodies_[i];
      s.position += h * b.v;
      const Quat dq(0.0, 0.5 * h * b.w.x(), 0.5 * h * b.w.y(), 0.5 * h * b.w.z());
      s.orientation.coeffs() += (dq * s.orientation).coeffs();
      s.orientation.normalize();
      s.rotation = s.orientation.toRotationMatrix();
    }
  }

  void finish_step(double h) {
    for (std::size_t i = 0; i < models_.size(); ++i) {
      auto& s = states_[i];
      s.force.setZero();
      s.torque.setZero();
      if (!is_moving(static_cast<BodyId>(i))) continue;
      const auto& b = solver_bodies_[i];
      s.linear_velocity = b.v;
      s.angular_velocity = b.w;
      if (!s.position.allFinite() || !s.orientation.coeffs().allFinite() || !b.v.allFinite() || !b.w.allFinite()) {
        ::manisoft::detail::diverged(static_cast<long>(step_count_), "body " + std::to_string(i) + describe(static_cast<BodyId>(i)),
                                     "rigid body ", i, describe(static_cast<BodyId>(i)), " has a non-finite state at step ",
                                     step_count_ + 1, " (t = ", time_ + h, " s): position (", s.position.transpose(),
                                     "), velocity (", b.v.transpose(), "), angular velocity (", b.w.transpose(),
                                     "); the world keeps its previous state");
      }
      const double speed = s.linear_velocity.norm(), spin = s.angular_velocity.norm();
      s.travel += h * (speed + spin * models_[i].bounding_radius);
      if (speed < settings_.sleep_linear_velocity && spin < settings_.sleep_angular_velocity) {
        s.sleep_time += h;
      } else {
        s.sleep_time = 0;
      }
    }
    time_ += h;
    ++step_count_;
    recording_ = false;
  }

  RigidWorldSettings settings_;
  std::vector<RigidBodyModel> models_;
  std::vector<RigidBodyState> states_;
  struct StepRecord {
    std::vector<RigidBodyState> states;
    struct ListOp {  // a change of the manifold list, in order
      std::uint32_t slot;
      bool removed;  // true: the manifold at `slot` was removed (its memory is next in `removed`)
    };
    std::vector<ListOp> ops;
    std::vector<contact::ManifoldMemory> removed;
    std::vector<std::pair<std::uint32_t, contact::ManifoldMemory>> manifolds;
    struct Box {
      std::uint32_t geom;
      Vec3 lo, hi;
    };
    std::vector<Box> boxes;
    bool broadphase_dirty{true};
    double time{0};
    std::uint64_t step_count{0};
  };
  StepRecord record_;  ///< what the current step changed (begin_step / undo_step)
  bool recording_{false};
  std::optional<ExcludedContact> excluded_;  // set_excluded_contact
  std::vector<RigidGeom> geoms_;
  std::vector<std::unique_ptr<detail::FatCollisionObject>> fcl_objects_;
  std::unique_ptr<fcl::DynamicAABBTreeCollisionManagerd> manager_;
  bool broadphase_dirty_{true};
  std::vector<std::uint64_t> pairs_;                               // see update_broadphase
  std::vector<std::pair<std::uint64_t, std::uint32_t>> old_pairs_;  // (key, slot)
  std::vector<std::uint64_t> keys_;                                // manifolds_[i].key(), compact
  std::vector<std::uint32_t> dropped_;                             // slots whose pair separated
  std::vector<std::uint32_t> moved_;   // geoms whose fat box moved this step
  std::vector<char> moved_flag_;       // per geom: in moved_ (set only inside update_broadphase)
  std::uint32_t query_geom_{0};        // the moved geom being queried
  std::vector<contact::ContactManifold*> active_;  // this step's active manifolds (points into manifolds_)
  std::vector<contact::ContactManifold> manifolds_;
  std::vector<contact::SolverBody> solver_bodies_;
  std::vector<std::uint32_t> parent_;
  std::vector<double> island_min_time_;
  contact::ContactSet contact_scratch_;
  contact::NarrowPhaseScratch scratch_;
  contact::SegmentCapsule query_capsule_;
  std::unique_ptr<detail::FatCollisionObject> query_object_;
  std::vector<std::uint32_t> query_candidates_;
  double time_{0};
  std::uint64_t step_count_{0};
};

}  // namespace manisoft::rigid
