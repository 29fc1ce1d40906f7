// Settling a rod to a static equilibrium by simulation: a rod with heavy uniform damping
// (SettlingRod: gravity, element torques and a tip load as the forcings) is stepped until every
// node moves slower than `speed` and every element spins slower than `spin` (checked every
// `check_interval` from `min_time` on), or `max_time` has passed. Used to find the poses the arm
// holds under given actuations (target sets, workspace maps) and in tests of static solutions.
#pragma once

#include <cmath>
#include <limits>

#include "manisoft/rod/cosserat_rod.hpp"

namespace manisoft::rod {

/// The rod used to find equilibria: PositionVerlet with uniform exponential damping.
template <typename Scalar>
using SettlingRod = CosseratRod<Scalar, damping::UniformExp, bc::ClampedBase, integrator::PositionVerlet, forcing::Gravity,
                                forcing::ElementTorques, forcing::TipLoad>;

template <typename Scalar>
struct SettleCriteria {
  Scalar max_time = Scalar(4);        ///< s: give up (not settled) after this
  Scalar min_time = Scalar(0);        ///< s: first check
  Scalar check_interval = Scalar(0.1);  ///< s between checks
  Scalar speed = Scalar(1e-4);        ///< m/s: every node slower
  Scalar spin = std::numeric_limits<Scalar>::infinity();  ///< rad/s: every element slower
};

/// Steps `rod` until it is at rest by `criteria` (returns true) or max_time passes or a step
/// diverges (returns false; the rod keeps the state before the failed step).
template <typename Rod, typename Scalar>
bool settle(Rod& rod, const SettleCriteria<Scalar>& criteria) {
  const auto steps_for = [&](Scalar seconds) { return static_cast<long>(std::lround(seconds / rod.dt())); };
  const long max_steps = steps_for(criteria.max_time), first = steps_for(criteria.min_time);
  const long every = std::max(1L, steps_for(criteria.check_interval));
  auto at_rest = [&] {
    return rod.state().velocities.rowwise().norm().maxCoeff() < criteria.speed &&
           rod.state().angular_velocities.rowwise().norm().maxCoeff() < criteria.spin;
  };
  try {
    long done = 0;
    if (first > 0) {
      rod.step(static_cast<int>(std::min(first, max_steps)));
      done = std::min(first, max_steps);
    }
    if (done >= first && at_rest()) return true;
    while (done < max_steps) {
      const long chunk = std::min(every, max_steps - done);
      rod.step(static_cast<int>(chunk));
      done += chunk;
      if (at_rest()) return true;
    }
  } catch (const Diverged&) {
    return false;
  }
  return false;
}

}  // namespace manisoft::rod
