// Actuation limits of the soft arm (ManiSoft paper, section 3.2: the policy outputs element
// torques tau in R^{N x 3}): the largest material-frame torque each actuated element can apply,
// |tau_1|, |tau_2| <= bend and |tau_3| <= twist. Element 0 sits on the clamped base and takes no
// torque. Every path that turns an action into rod torques (the arm world's control step, the
// action spaces, the inverse statics) clamps through clamp_to_limits, so the limits live here once.
#pragma once

#include <algorithm>
#include <cmath>

#include "manisoft/core/error.hpp"

namespace manisoft::rod {

/// Per-element actuation limits of the material-frame torques (N m).
template <typename Scalar>
struct ActuationLimits {
  Scalar bend = Scalar(150);
  Scalar twist = Scalar(75);
  Scalar limit(int component) const { return component < 2 ? bend : twist; }
  /// The bound of element `element`'s torque component `component` (element 0: none, zero).
  Scalar bound(int element, int component) const { return element == 0 ? Scalar(0) : limit(component); }
  void validate() const {
    manisoft::detail::require_positive("ActuationLimits bend", bend);
    manisoft::detail::require_positive("ActuationLimits twist", twist);
  }
};

/// Clamps every element torque (rows = elements, columns = d1, d2, d3) to the limits, element 0
/// to zero; returns the number of clamped entries of actuated elements.
template <typename Scalar, typename Torques>
int clamp_to_limits(const ActuationLimits<Scalar>& limits, Torques& torques) {
  int clamped = 0;
  for (int k = 0; k < torques.rows(); ++k)
    for (int c = 0; c < 3; ++c) {
      const Scalar lim = limits.bound(k, c);
      const Scalar t = torques(k, c);
      torques(k, c) = std::clamp(t, -lim, lim);
      if (k > 0 && std::abs(t) > lim) ++clamped;
    }
  return clamped;
}

}  // namespace manisoft::rod
