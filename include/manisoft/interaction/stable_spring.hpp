// Stiffness and damping of the explicit penalty springs of the interaction layer (rod-world
// contact, the gripper's weld): an explicit (symplectic Euler / leapfrog) step of a spring k on an
// effective mass m is stable for omega dt < 2 with omega = sqrt(k / m); the springs here are capped
// far below that, at omega dt <= max_omega_dt, so k <= m (max_omega_dt / dt)^2, and damped at a
// ratio zeta of critical, c = 2 zeta sqrt(k m).
#pragma once

#include <algorithm>
#include <cmath>

namespace manisoft::interaction {

/// min(k, m_eff (max_omega_dt / dt)^2): the stiffest spring with omega dt <= max_omega_dt.
inline double stable_stiffness(double stiffness, double effective_mass, double max_omega_dt, double dt) {
  const double omega = max_omega_dt / dt;
  return std::min(stiffness, effective_mass * omega * omega);
}

/// c = 2 zeta sqrt(k m): the damping of ratio zeta for a spring k on mass m.
inline double damping_for_ratio(double damping_ratio, double stiffness, double effective_mass) {
  return 2.0 * damping_ratio * std::sqrt(stiffness * effective_mass);
}

}  // namespace manisoft::interaction
