// CosseratRod: a discrete Cosserat rod (stretch, shear, bend, twist) composed at compile time
// from policy classes, integrated with PyElastica 1.0's discrete scheme so both agree to
// round-off (see internal_forces.hpp for the operators and integrators.hpp for the step order).
//
//   using Rod = manisoft::rod::CosseratRod<double, manisoft::rod::damping::AnalyticalLinear,
//                                     manisoft::rod::bc::ClampedBase,
//                                     manisoft::rod::integrator::PositionVerlet,
//                                     manisoft::rod::forcing::Gravity, manisoft::rod::forcing::ElementTorques>;
//   Rod rod(manisoft::rod::RodParameters<double>{}, 2e-4, manisoft::rod::damping::AnalyticalLinear<double>{0.1});
//   rod.forcing<manisoft::rod::forcing::ElementTorques>().set(torques);   // n x 3, material frame
//   rod.step();
//
// Guarantees: the constructor refuses bad parameters and a time step above the explicit
// stability limit (unless constructed with `allow_unstable_timestep`); a step allocates no heap
// memory; a step that meets a non-finite load or produces a non-finite or diverging state throws
// manisoft::Error naming the step and the element, and the state before that step is kept.
//
// Fast states: the explicit step resolves a rotation of at most about 0.1 rad per step; a rod
// driven far beyond its working loads (a coiled arm whipping at hundreds of m/s) rotates faster.
// A step whose fastest element turns more than 0.1 rad in dt is taken as m equal pieces of dt / m
// (m = ceil(|omega|max dt / 0.1), at most 64) with the loads of the step held and the damping
// applied once over dt; every other step is the plain scheme, unchanged.
#pragma once

#include <string>
#include <tuple>
#include <type_traits>

#include "manisoft/rod/boundary.hpp"
#include "manisoft/rod/damping.hpp"
#include "manisoft/rod/energies.hpp"
#include "manisoft/rod/forcing.hpp"
#include "manisoft/rod/integrators.hpp"
#include "manisoft/rod/internal_forces.hpp"
#include "manisoft/rod/kinematics.hpp"

namespace manisoft::rod {

/// Tag: build a rod even though its time step exceeds the explicit stability limit.
struct AllowUnstableTimestep {};
inline constexpr AllowUnstableTimestep allow_unstable_timestep{};

template <typename Scalar, template <class> class Damping = damping::None, template <class> class Boundary = bc::ClampedBase,
          typename Integrator = integrator::PositionVerlet, template <class> class... Forcings>
class CosseratRod {
  static_assert(std::is_floating_point_v<Scalar>, "CosseratRod needs a floating-point scalar");

 public:
  using Model = RodModel<Scalar>;
  using State = RodState<Scalar>;
  using Workspace = RodWorkspace<Scalar>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using DampingPolicy = Damping<Scalar>;
  using BoundaryPolicy = Boundary<Scalar>;

  /// A straight rod at rest described by `params`, stepped with `dt`. Policies not given are
  /// default-constructed (reach them later with damping() and forcing<F>()).
  CosseratRod(const RodParameters<Scalar>& params, Scalar dt) : CosseratRod(params, dt, DampingPolicy{}) {}
  CosseratRod(const RodParameters<Scalar>& params, Scalar dt, DampingPolicy damping)
    requires(sizeof...(Forcings) > 0)
      : CosseratRod(params, dt, std::move(damping), Forcings<Scalar>{}...) {}
  CosseratRod(const RodParameters<Scalar>& params, Scalar dt, DampingPolicy damping, Forcings<Scalar>... forcings)
      : CosseratRod(make_rod_model(params), make_straight_rod_state(params), dt, false, std::move(damping), std::move(forcings)...) {}

  /// The same, without the stability check (the caller owns the consequences).
  CosseratRod(AllowUnstableTimestep tag, const RodParameters<Scalar>& params, Scalar dt) : CosseratRod(tag, params, dt, DampingPolicy{}) {}
  CosseratRod(AllowUnstableTimestep tag, const RodParameters<Scalar>& params, Scalar dt, DampingPolicy damping)
    requires(sizeof...(Forcings) > 0)
      : CosseratRod(tag, params, dt, std::move(damping), Forcings<Scalar>{}...) {}
  CosseratRod(AllowUnstableTimestep, const RodParameters<Scalar>& params, Scalar dt, DampingPolicy damping, Forcings<Scalar>... forcings)
      : CosseratRod(make_rod_model(params), make_straight_rod_state(params), dt, true, std::move(damping), std::move(forcings)...) {}

  /// Any model and initial state (e.g. a pre-bent rod); the state must match the model's size.
  CosseratRod(Model model, State initial, Scalar dt, bool allow_unstable, DampingPolicy damping, Forcings<Scalar>... forcings)
      : model_(std::move(model)), state_(std::move(initial)), workspace_(model_.n_elements), dt_(dt),
        damping_(std::move(damping)), forcings_(std::move(forcings)...) {
    manisoft::detail::require_positive("dt", dt);
    check_state_shape(state_);
    model_.update_reciprocals();
    const Scalar limit = model_.stable_timestep_limit();
    if (!allow_unstable && dt > limit)
      manisoft::detail::fail("dt = ", dt, " s exceeds the explicit stability limit ", limit, " s of this rod (n_elements = ",
                   model_.n_elements, ", min element length ", model_.rest_lengths.minCoeff(),
                   " m); use a smaller dt, or construct with manisoft::rod::allow_unstable_timestep to override");
    damping_.setup(model_, dt_);
    std::apply([&](auto&... f) { (f.setup(model_), ...); }, forcings_);
    boundary_.setup(state_);
    backup_ = state_;  // sized once: step() copies into it without allocating
    compute_internal_forces_and_torques(model_, state_, workspace_);
  }

  // ---- stepping
  /// Advances the rod by dt. Throws manisoft::Error (state unchanged) on non-finite loads or state:
  /// InvalidInput for a non-finite load, Diverged for a non-finite or diverging state.
  void step() {
    backup_ = state_;
    try {
      advance();
    } catch (...) {
      state_ = backup_;
      throw;
    }
  }
  void step(int count) {
    for (int i = 0; i < count; ++i) step();
  }
  /// One dt without the rod's own backup, for assemblies that snapshot every part of a world once
  /// per step (world::SoftArmWorld): on an exception the state is partly advanced and the caller
  /// restores it with restore(). The step counter advances only on success.
  void advance() {
    step_start_time_ = state_.time;
    const int pieces = pieces_for_state();
    if (pieces == 1) {
      Integrator::step(*this, dt_);
    } else {
      const Scalar h = dt_ / Scalar(pieces);
      for (int i = 0; i < pieces; ++i) {
        damp_ = i + 1 == pieces;
        Integrator::step(*this, h);
      }
      damp_ = true;
    }
    last_pieces_ = pieces;
    check_state();
    ++step_count_;
    state_.external_forces.setZero();
    state_.external_torques.setZero();
  }
  /// Puts back a state and step counter saved before a failed advance() (no allocation: the
  /// state's arrays keep their size).
  void restore(const State& state, long step_count) {
    check_state_shape(state);
    state_ = state;
    step_count_ = step_count;
  }

  // ---- stages used by the integrator policies
  void kinematic(Scalar h) {
    update_kinematics(state_, h);
    state_.time += h;
    boundary_.constrain_values(state_);
  }
  void dynamic(Scalar h) {
    compute_internal_forces_and_torques(model_, state_, workspace_);
    workspace_.applied_forces = state_.external_forces;
    workspace_.applied_torques = state_.external_torques;
    std::apply([&](const auto&... f) { (f.apply(model_, state_, workspace_, workspace_.applied_forces, workspace_.applied_torques), ...); },
               forcings_);
    check_loads();
    for (int c = 0; c < 3; ++c) {
      Scalar* MANISOFT_RESTRICT v = detail::column(state_.velocities, c);
      const Scalar* MANISOFT_RESTRICT fi = workspace_.internal_forces.col(c).data();
      const Scalar* MANISOFT_RESTRICT fa = workspace_.applied_forces.col(c).data();
      const Scalar* MANISOFT_RESTRICT inv_m = model_.inv_node_masses.data();
      MANISOFT_VECTORIZE
      for (int k = 0; k <= model_.n_elements; ++k) v[k] += h * (fi[k] + fa[k]) * inv_m[k];
      Scalar* MANISOFT_RESTRICT w = detail::column(state_.angular_velocities, c);
      const Scalar* MANISOFT_RESTRICT ti = workspace_.internal_torques.col(c).data();
      const Scalar* MANISOFT_RESTRICT ta = workspace_.applied_torques.col(c).data();
      const Scalar* MANISOFT_RESTRICT inv_j = model_.inv_inertia.col(c).data();
      const Scalar* MANISOFT_RESTRICT e = workspace_.dilatation.data();
      MANISOFT_VECTORIZE
      for (int k = 0; k < model_.n_elements; ++k) w[k] += h * (ti[k] + ta[k]) * inv_j[k] * e[k];
    }
    boundary_.constrain_rates(state_);
  }
  void dampen() {
    if (damp_) damping_.dampen(model_, state_, workspace_);
  }

  // ---- access
  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  /// Mutable state: set initial conditions, or add external loads for the next step
  /// (external_forces on nodes in the lab frame, external_torques on elements in the material frame).
  State& state() { return state_; }
  const Workspace& workspace() const { return workspace_; }
  Scalar dt() const { return dt_; }
  /// Pieces the last step was split into (1 unless the state's rotation rate required more).
  int last_pieces() const { return last_pieces_; }
  Scalar time() const { return state_.time; }
  long step_count() const { return step_count_; }
  int n_elements() const { return model_.n_elements; }
  Vector3 tip_position() const { return state_.tip_position(); }
  DampingPolicy& damping() { return damping_; }
  BoundaryPolicy& boundary() { return boundary_; }
  template <template <class> class F>
  F<Scalar>& forcing() { return std::get<F<Scalar>>(forcings_); }
  template <template <class> class F>
  const F<Scalar>& forcing() const { return std::get<F<Scalar>>(forcings_); }

  /// Recomputes strains, stresses, internal forces and torques of the current state into the
  /// workspace (after a step they hold the values of the last force evaluation).
  const Workspace& refresh() {
    compute_internal_forces_and_torques(model_, state_, workspace_);
    return workspace_;
  }
  /// Energies of the current state; gravity is taken from a Gravity forcing if the rod has one.
  RodEnergies<Scalar> energies() {
    Vector3 g = Vector3::Zero();
    if constexpr ((std::is_same_v<Forcings<Scalar>, forcing::Gravity<Scalar>> || ...)) g = forcing<forcing::Gravity>().acceleration;
    return compute_energies(model_, state_, workspace_, g);
  }

 private:
  void check_state_shape(const State& s) const {
    const int n = model_.n_elements;
    if (s.positions.rows() != n + 1 || s.velocities.rows() != n + 1 || s.directors.rows() != n ||
        s.angular_velocities.rows() != n || s.external_forces.rows() != n + 1 || s.external_torques.rows() != n)
      manisoft::detail::fail("rod state does not match the model: expected ", n + 1, " nodes and ", n, " elements");
  }
  void check_loads() const {
    if (std::isfinite(workspace_.applied_forces.sum()) && std::isfinite(workspace_.applied_torques.sum())) return;
    for (int k = 0; k < workspace_.applied_forces.rows(); ++k)
      if (!workspace_.applied_forces.row(k).allFinite())
        manisoft::detail::fail("step ", step_count_, ": non-finite external force (", workspace_.applied_forces.row(k), ") on node ", k,
                     " refused; the rod keeps its state before the step");
    for (int k = 0; k < workspace_.applied_torques.rows(); ++k)
      if (!workspace_.applied_torques.row(k).allFinite())
        manisoft::detail::fail("step ", step_count_, ": non-finite external torque (", workspace_.applied_torques.row(k), ") on element ", k,
                     " refused; the rod keeps its state before the step");
    manisoft::detail::fail("step ", step_count_, ": external loads overflow");
  }
  void check_state() const {
    const Scalar sum = state_.positions.sum() + state_.velocities.sum() + state_.angular_velocities.sum() + state_.directors.sum();
    const Scalar e_min = workspace_.dilatation.minCoeff(), e_max = workspace_.dilatation.maxCoeff();
    const bool strain_ok = e_min > Scalar(0.01) && e_max < Scalar(100);
    if (std::isfinite(sum) && strain_ok) return;
    const int n = model_.n_elements;
    for (int k = 0; k <= n; ++k)
      if (!state_.positions.row(k).allFinite() || !state_.velocities.row(k).allFinite())
        manisoft::detail::diverged(step_count_, "node " + std::to_string(k), "step ", step_count_, " (t = ", step_start_time_, " s) produced a non-finite state at node ", k,
                     " (position ", state_.positions.row(k), ", velocity ", state_.velocities.row(k),
                     "); the rod keeps its state before the step. Is dt below the stability limit and are the loads bounded?");
    for (int k = 0; k < n; ++k)
      if (!state_.angular_velocities.row(k).allFinite() || !state_.directors.row(k).allFinite())
        manisoft::detail::diverged(step_count_, "element " + std::to_string(k), "step ", step_count_, " (t = ", step_start_time_, " s) produced a non-finite state at element ", k,
                     " (angular velocity ", state_.angular_velocities.row(k), "); the rod keeps its state before the step");
    int worst = 0;
    for (int k = 0; k < n; ++k)
      if (std::abs(std::log(workspace_.dilatation[k])) > std::abs(std::log(workspace_.dilatation[worst]))) worst = k;
    manisoft::detail::diverged(step_count_, "element " + std::to_string(worst), "step ", step_count_, " (t = ", step_start_time_, " s): the rod diverged, element ", worst, " has dilatation ",
                 workspace_.dilatation[worst], " (allowed 0.01 .. 100); the rod keeps its state before the step");
  }

  /// Equal pieces of dt this step takes: the fewest that keep every element's rotation per piece,
  /// |omega| h, within max_rotation_per_step (capped at max_pieces; a state beyond that diverges).
  int pieces_for_state() const {
    const Scalar w2 = state_.angular_velocities.rowwise().squaredNorm().maxCoeff();
    const Scalar turn = std::sqrt(w2) * dt_;
    if (!(turn > max_rotation_per_step)) return 1;
    return int(std::min<Scalar>(std::ceil(turn / max_rotation_per_step), Scalar(max_pieces)));
  }
  static constexpr Scalar max_rotation_per_step = Scalar(0.1);
  static constexpr int max_pieces = 64;

  Model model_;
  State state_;
  State backup_;
  Workspace workspace_;
  Scalar dt_;
  long step_count_ = 0;
  Scalar step_start_time_ = 0;
  bool damp_ = true;
  int last_pieces_ = 1;
  DampingPolicy damping_;
  BoundaryPolicy boundary_;
  std::tuple<Forcings<Scalar>...> forcings_;
};

}  // namespace manisoft::rod
