// The executor interface: a low-level controller that turns a target end-effector
// SE(3) pose, given in its observation, into an action.
//   Observation: the target pose, the current end-effector pose, and the lab-frame positions and
//                velocities of selected rod nodes (ascending node indices).
//   Executor:    reset() before an episode; act(observation, action) writes a rows x 3 action of
//                its action space (control/action_space.hpp): n x 3 element torques (columns
//                d1, d2, d3, N m) or K x 3 B-spline muscle control values. act() must not
//                allocate. ProjectedExecutor lets an element-torque executor drive any space.
// Executors see only the observation, never the simulator, so the end-effector model (a tip
// payload now, a gripper on a spring coupling later) can change without touching them.
#pragma once

#include <Eigen/Core>
#include <concepts>

#include "manisoft/core/error.hpp"
#include "manisoft/math/se3.hpp"

namespace manisoft::control {

template <typename Scalar>
struct Observation {
  math::Pose<Scalar> target;        ///< target end-effector pose (body to lab)
  math::Pose<Scalar> end_effector;  ///< current end-effector pose (body to lab)
  Eigen::VectorXi node_indices;     ///< observed rod nodes, strictly ascending
  Eigen::Matrix<Scalar, Eigen::Dynamic, 3> node_positions;   ///< lab frame, m (one row per observed node)
  Eigen::Matrix<Scalar, Eigen::Dynamic, 3> node_velocities;  ///< lab frame, m/s
  Scalar time = 0;                  ///< s since the episode started
};

template <typename T>
concept Executor = requires { typename T::Scalar; } &&
                   requires(T& executor, const Observation<typename T::Scalar>& observation,
                            Eigen::Matrix<typename T::Scalar, Eigen::Dynamic, 3>& action) {
                     { executor.reset() } -> std::same_as<void>;
                     { executor.act(observation, action) } -> std::same_as<void>;
                   };

/// Refuses a non-finite or non-rotation target and a malformed observation (manisoft::Error).
template <typename Scalar>
void validate_observation(const Observation<Scalar>& o, int n_nodes) {
  math::require_valid_pose(o.target, "executor target");
  const auto m = o.node_indices.size();
  if (m < 2 || o.node_positions.rows() != m || o.node_velocities.rows() != m)
    manisoft::detail::fail("executor: observation needs >= 2 observed nodes with one position and one velocity row each (got ",
                 m, " indices, ", o.node_positions.rows(), " positions, ", o.node_velocities.rows(), " velocities)");
  for (Eigen::Index i = 0; i < m; ++i) {
    if (o.node_indices[i] < 0 || o.node_indices[i] >= n_nodes || (i > 0 && o.node_indices[i] <= o.node_indices[i - 1]))
      manisoft::detail::fail("executor: observed node indices must be strictly ascending in [0, ", n_nodes - 1, "], entry ", i, " is ", o.node_indices[i]);
  }
}

}  // namespace manisoft::control
