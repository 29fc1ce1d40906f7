// The executor's observation of an arm world (paper section 3.4: the low-level executor sees the
// target pose, the end-effector pose and the arm's nodes), built one way for every world that
// holds the soft arm: the reach environment and the tabletop world (world::ArmWorld).
//
//   auto o = control::make_arm_observation<double>(n_elements, stride);   // node indices set once
//   control::observe_arm(world, target, o);                               // every control step
//
// Observed nodes: every `stride`-th node from the base, and always the tip. End-effector pose: the
// attachment frame of the end-effector body (the gripper: centre of the palm's top face, z = the
// approach axis). Positions and velocities are lab frame; time is the world's simulated time.
// observe_arm allocates nothing.
#pragma once

#include <Eigen/Core>

#include "manisoft/control/executor.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/math/se3.hpp"

namespace manisoft::control {

/// An observation with its node indices set (every `stride`-th node and the tip) and its node
/// rows sized; the poses are filled by observe_arm.
template <typename Scalar>
Observation<Scalar> make_arm_observation(int n_elements, int stride) {
  if (n_elements < 1) manisoft::detail::fail("make_arm_observation: n_elements = ", n_elements, " must be >= 1");
  if (stride < 1) manisoft::detail::fail("make_arm_observation: stride = ", stride, " must be >= 1");
  Observation<Scalar> o;
  int count = 0;
  for (int j = 0; j <= n_elements; j += stride) ++count;
  const bool tip_missing = (n_elements % stride) != 0;
  o.node_indices.resize(count + (tip_missing ? 1 : 0));
  int i = 0;
  for (int j = 0; j <= n_elements; j += stride) o.node_indices[i++] = j;
  if (tip_missing) o.node_indices[i] = n_elements;
  o.node_positions.setZero(o.node_indices.size(), 3);
  o.node_velocities.setZero(o.node_indices.size(), 3);
  return o;
}

/// Fills `o` (made by make_arm_observation for this arm) from an arm world: `world.rod()` and
/// `world.soft().end_effector_frame()` (world::ArmWorld, or any world with that interface).
template <typename World, typename Scalar>
void observe_arm(const World& world, const math::Pose<Scalar>& target, Observation<Scalar>& o) {
  const auto& s = world.rod().state();
  const auto frame = world.soft().end_effector_frame();
  o.target = target;
  o.end_effector = math::Pose<Scalar>{frame.rotation.template cast<Scalar>(), frame.position.template cast<Scalar>()};
  o.time = Scalar(s.time);
  for (Eigen::Index i = 0; i < o.node_indices.size(); ++i) {
    const int j = o.node_indices[i];
    if (j < 0 || j >= s.positions.rows()) manisoft::detail::fail("observe_arm: observed node ", j, " is not a node of the arm (", s.positions.rows(), " nodes)");
    o.node_positions.row(i) = s.positions.row(j).template cast<Scalar>();
    o.node_velocities.row(i) = s.velocities.row(j).template cast<Scalar>();
  }
}

}  // namespace manisoft::control
