// BatchedReachEnv: B independent reach environments (env/reach_env.hpp, one configuration for all)
// stepped by one call over a persistent pool of threads (core/worker_pool.hpp), with batched
// observation, reward, done and info arrays: the vectorised environment a learner trains on (the
// paper's executor training, appendix "Details for Executor Training", runs many arms at once).
//
//   BatchedReachEnv<> batch(B, threads, config, damping);
//   batch.reset(seeds);                       // B seeds: one episode per arm
//   batch.step(actions);                      // B x rows x 3 doubles, row-major
//   batch.rewards()[i], batch.terminated()[i], batch.end_effector() ...
//
// Layout. Every array is owned by the batch, contiguous, row-major with the arm as its leading
// dimension, allocated once and overwritten by every reset and step (a binding hands it over
// without a copy; a caller that keeps values across steps copies them):
//   end_effector, target   B x 4 x 4   homogeneous poses (body to lab; last row 0 0 0 1)
//   node_positions         B x m x 3   observed nodes (every observe_stride-th and the tip), m
//   node_velocities        B x m x 3   m/s
//   rewards                B           R_d + R_s of the step (0 after a reset)
//   terminated             B           1: the arm's simulation diverged in this step
//   truncated              B           1: the horizon was reached in this step (not terminated)
//   success                B           1: the episode has held the tolerance for hold_steps
//   steps                  B           control steps of the current episode
//   position_error, rotation_error  B  |d_p| m and |d_r| rad of the end effector to the target
//   clipped                B           element torque entries clamped to the limits in the step
//   max_node_speed         B           m/s, fastest node at any substep of the step
//   seeds                  B           the seed of each arm's current episode
// Flags are std::uint8_t 0 / 1 (a numpy bool view of the same bytes).
// Actions: arm i's entry (r, c) at actions[(i * rows + r) * 3 + c], rows = action_space().rows().
//
// Autoreset (Gymnasium 1.x NEXT_STEP): an arm whose episode ended (terminated or truncated) in one
// step() is reset by the next step(): its action in that call is ignored (not even checked), its
// observation is the new episode's first, its reward 0, its flags and steps 0. The new episode's
// seed is the ended one's plus B, so arms started with seeds s, s + 1, ..., s + B - 1 visit every
// seed from s upwards once. reset() and reset(mask, seeds) clear a pending autoreset of the arms
// they reset.
//
// Determinism: arms are split over threads in contiguous chunks and share nothing, so an arm's
// trajectory is bit-identical to a ReachEnv stepped alone with the same seeds and actions, whatever
// the thread count and the arm's position in the batch.
// Bad input (wrong sizes, a non-finite action of an arm that steps) is refused with InvalidInput
// naming the arm and the entry before any arm changes. step() allocates nothing while no arm
// resets; an autoreset builds the arm's new world (as ReachEnv::reset does).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/core/worker_pool.hpp"
#include "manisoft/env/reach_env.hpp"

namespace manisoft::env {

template <template <class> class Damping = rod::damping::AnalyticalLinear,
          template <class> class ActionPolicy = control::ElementTorqueAction>
class BatchedReachEnv {
 public:
  using Env = ReachEnv<Damping, ActionPolicy>;
  using Action = typename Env::Action;

  BatchedReachEnv(int batch_size, int threads, ReachEnvConfig config, Damping<double> damping,
                  typename Action::Settings action_settings = {})
      : pool_(threads) {
    if (batch_size < 1) manisoft::detail::fail("BatchedReachEnv: batch_size = ", batch_size, " must be >= 1");
    arms_.resize(std::size_t(batch_size));
    // each arm builds its inverse statics: spread over the threads
    for_each_arm([&](std::size_t i) { arms_[i] = std::make_unique<Env>(config, damping, action_settings); });
    rows_ = arms_[0]->action_space().rows();
    observed_ = int(control::make_arm_observation<double>(config.rod.n_elements, config.observe_stride).node_indices.size());
    const typename Env::Array3 zero = Env::Array3::Zero(rows_, 3);
    actions_.assign(std::size_t(batch_size), zero);
    allocate(std::size_t(batch_size));
  }

  int batch_size() const { return int(arms_.size()); }
  int threads() const { return pool_.threads(); }
  /// Rows of one arm's action (3 columns).
  int action_rows() const { return rows_; }
  /// Observed nodes per arm (m).
  int observed_nodes() const { return observed_; }
  const Action& action_space() const { return arms_[0]->action_space(); }
  /// Arm i's environment (its target, rod, world, info).
  const Env& arm(int i) const { return *arms_.at(std::size_t(i)); }

  /// Starts a new episode on every arm, arm i with seeds[i].
  void reset(std::span<const std::uint64_t> seeds) {
    require_size("seeds", seeds.size());
    std::fill(do_reset_.begin(), do_reset_.end(), std::uint8_t(1));
    reset_marked(seeds);
  }

  /// Starts a new episode on the arms with mask[i] != 0, arm i with seeds[i] (the other seeds are
  /// ignored); the other arms and their arrays are left as they are.
  void reset(std::span<const std::uint8_t> mask, std::span<const std::uint64_t> seeds) {
    if (!started_) manisoft::detail::fail("BatchedReachEnv::reset(mask, seeds) called before reset(seeds) started every arm");
    require_size("mask", mask.size());
    require_size("seeds", seeds.size());
    for (std::size_t i = 0; i < mask.size(); ++i) do_reset_[i] = mask[i] != 0;
    reset_marked(seeds);
  }

  /// One control step of every arm (arms whose episode ended in the previous step reset instead).
  void step(std::span<const double> actions) {
    if (!started_) manisoft::detail::fail("BatchedReachEnv::step called before reset");
    const std::size_t per_arm = std::size_t(rows_) * 3;
    if (actions.size() != arms_.size() * per_arm)
      manisoft::detail::fail("BatchedReachEnv::step: actions hold ", actions.size(), " values, expected batch_size x rows x 3 = ",
                             arms_.size(), " x ", rows_, " x 3 = ", arms_.size() * per_arm);
    for (std::size_t i = 0; i < arms_.size(); ++i) {
      if (pending_reset_[i]) continue;
      for (std::size_t k = 0; k < per_arm; ++k)
        if (!std::isfinite(actions[i * per_arm + k]))
          manisoft::detail::fail("BatchedReachEnv::step: arm ", i, ": action entry (", k / 3, ", ", k % 3, ") = ", actions[i * per_arm + k],
                                 " is not finite");
    }
    for_each_arm([this, actions](std::size_t i) { step_arm(i, actions); });
  }

  std::span<const double> end_effector() const { return end_effector_; }
  std::span<const double> target() const { return target_; }
  std::span<const double> node_positions() const { return node_positions_; }
  std::span<const double> node_velocities() const { return node_velocities_; }
  std::span<const double> rewards() const { return rewards_; }
  std::span<const std::uint8_t> terminated() const { return terminated_; }
  std::span<const std::uint8_t> truncated() const { return truncated_; }
  std::span<const std::uint8_t> success() const { return success_; }
  std::span<const std::int32_t> steps() const { return steps_; }
  std::span<const double> position_error() const { return position_error_; }
  std::span<const double> rotation_error() const { return rotation_error_; }
  std::span<const std::int32_t> clipped() const { return clipped_; }
  std::span<const double> max_node_speed() const { return max_node_speed_; }
  std::span<const std::uint64_t> seeds() const { return seeds_; }

 private:
  void allocate(std::size_t b) {
    const std::size_t nodes = b * std::size_t(observed_) * 3;
    end_effector_.assign(b * 16, 0.0);
    target_.assign(b * 16, 0.0);
    node_positions_.assign(nodes, 0.0);
    node_velocities_.assign(nodes, 0.0);
    rewards_.assign(b, 0.0);
    position_error_.assign(b, 0.0);
    rotation_error_.assign(b, 0.0);
    max_node_speed_.assign(b, 0.0);
    terminated_.assign(b, 0);
    truncated_.assign(b, 0);
    success_.assign(b, 0);
    pending_reset_.assign(b, 0);
    do_reset_.assign(b, 0);
    steps_.assign(b, 0);
    clipped_.assign(b, 0);
    seeds_.assign(b, 0);
  }

  void require_size(const char* what, std::size_t size) const {
    if (size != arms_.size())
      manisoft::detail::fail("BatchedReachEnv::reset: ", what, " hold ", size, " values, expected batch_size = ", arms_.size());
  }

  /// Threads a call uses: no more than there are arms.
  int active_threads() const { return std::min(pool_.threads(), int(arms_.size())); }

  std::size_t chunk_begin(int part, int parts) const { return arms_.size() * std::size_t(part) / std::size_t(parts); }

  /// Calls f(i) for every arm i over the pool: each thread takes a contiguous chunk of arms.
  template <typename F>
  void for_each_arm(F&& f) {
    auto job = [this, &f](int part, int parts) {
      for (std::size_t i = chunk_begin(part, parts); i < chunk_begin(part + 1, parts); ++i) f(i);
    };
    pool_.run(job, active_threads());
  }

  void reset_marked(std::span<const std::uint64_t> seeds) {
    for_each_arm([this, seeds](std::size_t i) {
      if (do_reset_[i]) reset_arm(i, seeds[i]);
    });
    started_ = true;
  }

  void reset_arm(std::size_t i, std::uint64_t seed) {
    const control::Observation<double>& o = arms_[i]->reset(seed);
    seeds_[i] = seed;
    pending_reset_[i] = 0;
    rewards_[i] = 0;
    terminated_[i] = truncated_[i] = success_[i] = 0;
    steps_[i] = clipped_[i] = 0;
    max_node_speed_[i] = 0;
    write_observation(i, o);
    const reward::PoseError<double> e = reward::pose_error(o.end_effector, o.target);
    position_error_[i] = e.position_error;
    rotation_error_[i] = e.rotation_error;
  }

  void step_arm(std::size_t i, std::span<const double> actions) {
    if (pending_reset_[i]) {
      reset_arm(i, seeds_[i] + arms_.size());
      return;
    }
    typename Env::Array3& a = actions_[i];
    const double* in = actions.data() + i * std::size_t(rows_) * 3;
    for (int r = 0; r < rows_; ++r)
      for (int c = 0; c < 3; ++c) a(r, c) = in[r * 3 + c];
    const typename Env::StepResult result = arms_[i]->step(a);
    const ReachInfo& info = result.info;
    rewards_[i] = result.reward;
    terminated_[i] = info.diverged;
    truncated_[i] = !info.diverged && info.step >= arms_[i]->config().horizon;
    pending_reset_[i] = result.done;
    success_[i] = info.success;
    steps_[i] = info.step;
    clipped_[i] = info.clipped;
    max_node_speed_[i] = info.max_node_speed;
    position_error_[i] = info.error.position_error;
    rotation_error_[i] = info.error.rotation_error;
    write_observation(i, result.observation);
  }

  static void write_pose(const math::Pose<double>& pose, double* out) {
    Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> matrix(out);
    matrix = pose.matrix();
  }

  void write_observation(std::size_t i, const control::Observation<double>& o) {
    write_pose(o.end_effector, end_effector_.data() + i * 16);
    write_pose(o.target, target_.data() + i * 16);
    const std::size_t base = i * std::size_t(observed_) * 3;
    for (int k = 0; k < observed_; ++k)
      for (int c = 0; c < 3; ++c) {
        node_positions_[base + std::size_t(k) * 3 + std::size_t(c)] = o.node_positions(k, c);
        node_velocities_[base + std::size_t(k) * 3 + std::size_t(c)] = o.node_velocities(k, c);
      }
  }

  std::vector<std::unique_ptr<Env>> arms_;
  std::vector<typename Env::Array3> actions_;  ///< one per arm, the action read from the batch
  int rows_ = 0;
  int observed_ = 0;
  bool started_ = false;
  std::vector<double> end_effector_, target_, node_positions_, node_velocities_;
  std::vector<double> rewards_, position_error_, rotation_error_, max_node_speed_;
  std::vector<std::uint8_t> terminated_, truncated_, success_;
  std::vector<std::uint8_t> pending_reset_;  ///< the episode ended: the next step resets the arm
  std::vector<std::uint8_t> do_reset_;       ///< the arms the running reset call resets
  std::vector<std::int32_t> steps_, clipped_;
  std::vector<std::uint64_t> seeds_;
  WorkerPool pool_;  ///< last: its threads are joined before the arms go
};

}  // namespace manisoft::env
