// ManiSoft error reporting: one exception type for every refused input or diverged state.
// Messages name the offending value, the limit it broke and, where it applies, the element or
// step, so a user can fix the call without reading our code.
#pragma once

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace manisoft {

/// Thrown for invalid parameters, malformed input files, unstable time steps and non-finite
/// states. The object that threw keeps its last valid state.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

namespace detail {

/// Builds an Error message from streamable parts: fail("youngs_modulus = ", E, " must be > 0").
template <typename... Parts>
[[noreturn]] void fail(Parts&&... parts) {
  std::ostringstream out;
  out.precision(17);
  (out << ... << std::forward<Parts>(parts));
  throw Error(out.str());
}

/// Refuses a parameter that is not finite or not strictly positive.
template <typename Scalar>
void require_positive(const char* name, Scalar value) {
  if (!std::isfinite(value) || !(value > Scalar(0))) {
    fail(name, " = ", value, " is invalid: it must be finite and > 0");
  }
}

/// Refuses a parameter that is not finite or negative.
template <typename Scalar>
void require_non_negative(const char* name, Scalar value) {
  if (!std::isfinite(value) || value < Scalar(0)) {
    fail(name, " = ", value, " is invalid: it must be finite and >= 0");
  }
}

/// Refuses a non-finite parameter.
template <typename Scalar>
void require_finite(const char* name, Scalar value) {
  if (!std::isfinite(value)) fail(name, " = ", value, " is invalid: it must be finite");
}

}  // namespace detail
}  // namespace manisoft
