// ReachEnv: the executor benchmark environment (ManiSoft paper, section 3.4 and appendix): reach
// a target end-effector SE(3) pose with the soft arm and hold it.
//
//   env.reset(seed) -> observation;  env.step(action) -> {observation, reward, done, info}
//
// The arm is the benchmark's arm world (world::ArmWorld, world frame of world/tabletop_scene.hpp:
// floor z = 0, table plane z = 0.75, base at (-0.05, 0, 1.5) pointing +x): the paper's rod (n = 20,
// L = 1 m, r = 0.05 m, rho = 1000, E = 1e7, G = E/3), dt = 2e-4 s, 7 substeps per control step
// (714 Hz), horizon 1500, the parallel gripper on the arm world's coupling; configured without a
// table and without rod contact (free space). A held load (`load_mass`) rides in the closed
// gripper: it is added to the gripper body's mass. `model_error` F makes the simulated Young's
// modulus (1 + F) times the nominal one; nominal_model() is what an executor should assume.
// Action: a policy class (control/action_space.hpp), ElementTorqueAction (n x 3 material-frame
// element torques, the default) or BsplineMuscleAction (K x 3 muscle control values); the arm
// world's control step clamps the element torques to the actuation limits (|tau_1|, |tau_2| <=
// 150 N m, |tau_3| <= 75 N m; element 0 takes none); info.clipped counts the clamped entries.
// Observation: target, end-effector pose (the gripper's attachment frame: centre of the palm's
// top face), positions and velocities of every `observe_stride`-th node (always the tip).
// Reward: R = R_d + R_s of the paper (d = |d_p| + 0.2 |d_r|; k1 = 0.5, k2 = 1.5, d1 = 0.1,
// d2 = 0.05; config.stability: beta = 1, D = 0.3 by default). Success: within tolerance, then
// held for `hold_steps` control steps (first_success_step is the first step of that held window). A diverged simulation step
// ends the episode (info.diverged; the world keeps its state before the step); invalid input
// (a malformed action) is refused with manisoft::InvalidInput and changes nothing.
//
// Target sets (seeded; every target is held at equilibrium by the nominal model within the
// actuation limits, checked with the inverse statics, else redrawn), relative to the arm's base:
//   table       the gripper above the table plane, pointing down: position uniform in
//               x in [0.40, 0.85], y in [-0.25, 0.25], z in [-0.70, -0.30] m from the base (the
//               table plane is 0.75 m below it), tool axis d3 within 45 deg of -z (uniform on the
//               cap), any yaw.
//   equilibria  tip poses where the arm settles under random bounded actuation: per axis a
//               random quadratic torque profile along the arm (|tau| <= 10 N m bend, 4 N m
//               twist) plus a random tip-element couple (<= 60 N m bend, 20 N m twist), settled
//               with heavy uniform damping; actuations that do not settle within 4 s
//               (follower-torque flutter) or whose pose the inverse statics cannot hold within
//               the limits are redrawn.
// docs/executors.md describes both sets; BENCHMARKS.md has the executor's results on them.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <random>
#include <string>

#include "manisoft/control/action_space.hpp"
#include "manisoft/control/arm_observation.hpp"
#include "manisoft/control/executor.hpp"
#include "manisoft/control/tool_down.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/reward/distance_reward.hpp"
#include "manisoft/reward/pose_distance.hpp"
#include "manisoft/reward/stability_reward.hpp"
#include "manisoft/reward/sum.hpp"
#include "manisoft/rod/cosserat_rod.hpp"
#include "manisoft/rod/inverse_statics.hpp"
#include "manisoft/rod/settle.hpp"
#include "manisoft/world/arm_world.hpp"
#include "manisoft/world/tabletop_scene.hpp"

namespace manisoft::env {

enum class TargetSet { table, equilibria };

inline TargetSet parse_target_set(const std::string& name) {
  if (name == "table") return TargetSet::table;
  if (name == "equilibria") return TargetSet::equilibria;
  manisoft::detail::fail("unknown target set '", name, "': expected table or equilibria");
}

struct ReachEnvConfig {
  rod::RodParameters<double> rod = world::tabletop_arm_parameters();  ///< nominal arm, mounted in the world frame
  double dt = 2e-4;                         ///< s
  int substeps = 7;                         ///< simulation steps per control step (714 Hz)
  int horizon = 1500;                       ///< control steps per episode
  double gripper_mass = 0.2;                ///< kg, known to the executor's model
  interaction::ElasticSpringParameters coupling = interaction::ElasticSpringParameters::arm();  ///< rod tip <-> gripper
  double load_mass = 0;                     ///< kg, held load unknown to the model
  double model_error = 0;                   ///< F: simulated E = (1 + F) E_nominal
  int observe_stride = 2;                   ///< observe every k-th node (and the tip)
  TargetSet target_set = TargetSet::table;
  rod::ActuationLimits<double> limits{150, 75};
  double tolerance_position = 0.03;         ///< m, on |d_p|
  double tolerance_rotation = 0.3;          ///< rad, on |d_r|
  int hold_steps = 100;                     ///< control steps the tolerance must hold
  int stability_window = 1000;              ///< simulation steps of the stability variance
  reward::StabilityRewardParameters<double> stability{};  ///< R_s (beta = 0: R_d alone)
};

struct ReachInfo {
  reward::PoseError<double> error{};
  bool in_tolerance = false;
  bool success = false;            ///< held within tolerance for hold_steps
  int first_success_step = -1;     ///< first control step of the held window, -1 if none
  int step = 0;                    ///< control steps taken
  bool diverged = false;           ///< the simulated rod refused a step (state kept)
  int clipped = 0;                 ///< element torque entries clamped to the limits in this step
  double max_node_speed = 0;       ///< m/s, the fastest rod node at any substep of this step
};

template <template <class> class Damping = rod::damping::AnalyticalLinear,
          template <class> class ActionPolicy = control::ElementTorqueAction>
class ReachEnv {
 public:
  using Action = ActionPolicy<double>;
  static_assert(control::ActionSpace<Action>);
  using Rod = rod::CosseratRod<double, Damping, rod::bc::ClampedBase, rod::integrator::PositionVerlet, rod::forcing::Gravity,
                          rod::forcing::ElementTorques>;
  using World = world::ArmWorld<Rod>;
  using Info = ReachInfo;
  using Array3 = Eigen::Matrix<double, Eigen::Dynamic, 3>;
  using Pose = math::Pose<double>;
  using Reward = reward::Sum<reward::DistanceReward<double>, reward::StabilityReward<double>>;

  struct StepResult {
    const control::Observation<double>& observation;
    double reward;
    bool done;
    ReachInfo info;
  };

  ReachEnv(ReachEnvConfig config, Damping<double> damping, typename Action::Settings action_settings = {})
      : config_(config), damping_(damping), action_space_(config.rod.n_elements, config.rod.length, config.limits, action_settings),
        nominal_(rod::make_arm_model(config.rod, config.gripper_mass)),
        statics_(nominal_, {}, config.limits) {
    manisoft::detail::require_positive("dt", config_.dt);
    if (config_.substeps < 1) manisoft::detail::fail("substeps = ", config_.substeps, " must be >= 1");
    if (config_.horizon < 1) manisoft::detail::fail("horizon = ", config_.horizon, " must be >= 1");
    manisoft::detail::require_positive("gripper_mass", config_.gripper_mass);
    manisoft::detail::require_non_negative("load_mass", config_.load_mass);
    if (!std::isfinite(config_.model_error) || config_.model_error <= -0.9)
      manisoft::detail::fail("model_error = ", config_.model_error, " is invalid: it must be finite and > -0.9");
    if (config_.observe_stride < 1) manisoft::detail::fail("observe_stride = ", config_.observe_stride, " must be >= 1");
    manisoft::detail::require_positive("tolerance_position", config_.tolerance_position);
    manisoft::detail::require_positive("tolerance_rotation", config_.tolerance_rotation);
    if (config_.hold_steps < 1) manisoft::detail::fail("hold_steps = ", config_.hold_steps, " must be >= 1");
    if (config_.stability_window < 1) manisoft::detail::fail("stability_window = ", config_.stability_window, " must be >= 1");
    reward_ = Reward(reward::DistanceReward<double>{}, reward::StabilityReward<double>(config_.stability));  // checks the parameters
    const int n = config_.rod.n_elements;
    observation_ = control::make_arm_observation<double>(n, config_.observe_stride);
    d_history_.setZero(config_.stability_window);
    element_torques_.setZero(n, 3);
  }

  /// The model an executor should assume: nominal stiffness, gripper payload, no load.
  const rod::ArmModel<double>& nominal_model() const { return nominal_; }
  const ReachEnvConfig& config() const { return config_; }
  int n_elements() const { return config_.rod.n_elements; }
  /// The action space: rows() x 3 actions, apply() to element torques, project() from them.
  const Action& action_space() const { return action_space_; }
  /// The last observation (before the first reset: zeros, laid out as every later one).
  const control::Observation<double>& observation() const { return observation_; }

  /// Starts an episode: draws the target of `seed` and puts the arm straight at rest.
  const control::Observation<double>& reset(std::uint64_t seed) {
    target_ = draw_target(seed);
    rod::RodParameters<double> sim = config_.rod;
    sim.youngs_modulus *= 1 + config_.model_error;
    if (config_.rod.shear_modulus > 0) sim.shear_modulus *= 1 + config_.model_error;
    world::ArmWorldSettings settings;
    settings.gripper.mass = config_.gripper_mass + config_.load_mass;
    settings.coupling = config_.coupling;
    settings.rod_contact_enabled = false;
    settings.limits = config_.limits;
    settings.substeps_per_control_step = config_.substeps;
    world_.emplace(Rod(sim, config_.dt, damping_), settings);
    reward_ = Reward(reward::DistanceReward<double>{}, reward::StabilityReward<double>(config_.stability));
    info_ = ReachInfo{};
    held_ = 0;
    d_count_ = 0;
    fill_observation();
    return observation_;
  }

  /// Applies `action` (action_space().rows() x 3; element torques clamped to the limits) for
  /// one control step. A malformed or non-finite action is refused before anything changes.
  StepResult step(const Array3& action) {
    if (!world_) manisoft::detail::fail("ReachEnv::step called before reset");
    action_space_.apply(action, element_torques_);
    info_.clipped = 0;
    info_.max_node_speed = 0;
    if (!info_.diverged) {
      try {
        info_.clipped = world_->control_step(element_torques_, 0, [this] { record_distance(); });
      } catch (const Diverged&) {
        info_.diverged = true;
      }
    }
    ++info_.step;
    fill_observation();
    info_.error = reward::pose_error(observation_.end_effector, target_);
    info_.in_tolerance = !info_.diverged && info_.error.position_error < config_.tolerance_position &&
                         info_.error.rotation_error < config_.tolerance_rotation;
    held_ = info_.in_tolerance ? held_ + 1 : 0;
    if (!info_.success && held_ >= config_.hold_steps) {
      info_.success = true;
      info_.first_success_step = info_.step - config_.hold_steps;
    }
    const reward::RewardInput<double> input{observation_.end_effector, target_,
                                            config_.dt * config_.substeps, !info_.diverged};
    const double r = reward_.evaluate(input).total;
    const bool done = info_.diverged || info_.step >= config_.horizon;
    return StepResult{observation_, r, done, info_};
  }

  const Pose& target() const { return target_; }
  const ReachInfo& info() const { return info_; }
  const Rod& rod() const { return world_->rod(); }
  /// The tabletop world's arm frame: where the target sets are drawn from.
  const Eigen::Vector3d& base_position() const { return config_.rod.base_position; }
  const World& world() const { return *world_; }
  /// Variance of d over the last stability_window simulation steps (fewer if not yet run).
  double stability_variance() const {
    const long m = std::min<long>(d_count_, config_.stability_window);
    if (m < 2) return 0;
    double mean = 0;
    for (long i = 0; i < m; ++i) mean += d_history_[i];
    mean /= double(m);
    double var = 0;
    for (long i = 0; i < m; ++i) var += (d_history_[i] - mean) * (d_history_[i] - mean);
    return var / double(m);
  }
  /// Candidate poses drawn for the last target (1 = the first was reachable).
  int target_draws() const { return target_draws_; }

  /// The target of `seed` in this environment's set (deterministic).
  Pose draw_target(std::uint64_t seed) {
    std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 0x5EED);
    for (target_draws_ = 1; target_draws_ <= 500; ++target_draws_) {
      std::optional<Pose> candidate =
          config_.target_set == TargetSet::table ? table_candidate(rng) : equilibrium_candidate(rng);
      if (!candidate) continue;
      const auto r = statics_.solve_cold(*candidate);
      if (r.within_limits) return *candidate;
    }
    manisoft::detail::fail("ReachEnv: no reachable target found for seed ", seed, " in 500 draws");
  }

 private:
  static double uniform(std::mt19937_64& rng, double lo, double hi) {
    return lo + (hi - lo) * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
  }

  std::optional<Pose> table_candidate(std::mt19937_64& rng) const {
    const double pi = std::numbers::pi;
    const Eigen::Vector3d p = config_.rod.base_position +
                              Eigen::Vector3d(uniform(rng, 0.40, 0.85), uniform(rng, -0.25, 0.25), uniform(rng, -0.70, -0.30));
    const double yaw = uniform(rng, -pi, pi);
    const double tilt = std::acos(1 - uniform(rng, 0, 1) * (1 - std::cos(pi / 4)));
    const double tilt_dir = uniform(rng, 0, 2 * pi);
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(tilt, Eigen::Vector3d(std::cos(tilt_dir), std::sin(tilt_dir), 0)).toRotationMatrix() * control::tool_down_rotation(yaw);
    return Pose{r, p};
  }

  std::optional<Pose> equilibrium_candidate(std::mt19937_64& rng) const {
    const int n = n_elements();
    Array3 torques = Array3::Zero(n, 3);
    for (int c = 0; c < 3; ++c) {
      const double amplitude = c < 2 ? 10.0 : 4.0;
      const double a0 = uniform(rng, -1, 1), a1 = uniform(rng, -1, 1), a2 = uniform(rng, -1, 1);
      double peak = 0;
      for (int k = 1; k < n; ++k) {
        const double s = double(k) / double(n - 1);
        torques(k, c) = a0 + a1 * s + a2 * s * s;
        peak = std::max(peak, std::abs(torques(k, c)));
      }
      const double scale = amplitude * uniform(rng, 0, 1) / std::max(peak, 1e-12);
      torques.col(c) *= scale;
      torques(n - 1, c) += uniform(rng, -1, 1) * (c < 2 ? 60.0 : 20.0);
    }
    rod::forcing::TipLoad<double> tip;
    tip.force_lab = rod::forcing::Gravity<double>{}.acceleration * config_.gripper_mass;
    rod::SettlingRod<double> rod(config_.rod, config_.dt, rod::damping::UniformExp<double>(20.0), rod::forcing::Gravity<double>{},
                                 rod::forcing::ElementTorques<double>{}, tip);
    rod.template forcing<rod::forcing::ElementTorques>().set(torques);
    rod::SettleCriteria<double> rest;  // 4 s, then at rest or redrawn
    rest.min_time = rest.max_time = 4.0;
    rest.speed = 1e-4;
    rest.spin = 1e-3;
    if (!rod::settle(rod, rest)) return std::nullopt;
    return rod.state().tip_pose();
  }

  Pose end_effector() const {
    const auto frame = world_->soft().end_effector_frame();
    return Pose{frame.rotation, frame.position};
  }

  void record_distance() {
    d_history_[d_count_ % config_.stability_window] = reward::pose_error(end_effector(), target_).distance;
    ++d_count_;
    info_.max_node_speed = std::max(info_.max_node_speed, world_->rod().state().velocities.rowwise().norm().maxCoeff());
  }

  void fill_observation() { control::observe_arm(*world_, target_, observation_); }

  ReachEnvConfig config_;
  Damping<double> damping_;
  Action action_space_;
  rod::ArmModel<double> nominal_;
  rod::InverseStatics<double> statics_;
  std::optional<World> world_;
  Reward reward_;
  Pose target_;
  control::Observation<double> observation_;
  ReachInfo info_;
  int held_ = 0;
  int target_draws_ = 0;
  Eigen::VectorXd d_history_;
  long d_count_ = 0;
  Array3 element_torques_;
};

}  // namespace manisoft::env
