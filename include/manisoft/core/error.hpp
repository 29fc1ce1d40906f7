// ManiSoft error reporting, by kind: InvalidInput (a parameter, action, file or call the library
// refuses before changing anything) and Diverged (a simulation step that produced a non-finite
// or diverging state: the simulation keeps its state from before that step). Both derive from
// Error, so `catch (const Error&)` still sees everything; an environment that must go on after a
// blown-up step catches Diverged only and lets programming errors through.
// Messages name the offending value, the limit it broke and, where it applies, the element or
// step, so a user can fix the call without reading our code.
#pragma once

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace manisoft {

/// Base of every ManiSoft exception. The object that threw keeps its last valid state.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// Invalid parameters, malformed files, unstable time steps, non-finite actions or loads, calls
/// out of order: refused before anything changed.
class InvalidInput : public Error {
 public:
  using Error::Error;
};

/// A simulation step produced a non-finite or diverging state; the simulation was put back to
/// its state before that step. `step` is the step that failed; `where` names the rod node or
/// element, or the rigid body ("element 7", "body 3 ('cube')").
class Diverged : public Error {
 public:
  Diverged(const std::string& message, long step, std::string where)
      : Error(message), step_(step), where_(std::move(where)) {}
  long step() const { return step_; }
  const std::string& where() const { return where_; }

 private:
  long step_;
  std::string where_;
};

namespace detail {

template <typename... Parts>
std::string message(Parts&&... parts) {
  std::ostringstream out;
  out.precision(17);
  (out << ... << std::forward<Parts>(parts));
  return out.str();
}

/// Refuses an input: throws InvalidInput built from streamable parts:
/// fail("youngs_modulus = ", E, " must be > 0").
template <typename... Parts>
[[noreturn]] void fail(Parts&&... parts) {
  throw InvalidInput(message(std::forward<Parts>(parts)...));
}

/// Reports a diverged step (`step`, at `where`): throws Diverged built from streamable parts.
template <typename... Parts>
[[noreturn]] void diverged(long step, const std::string& where, Parts&&... parts) {
  throw Diverged(message(std::forward<Parts>(parts)...), step, where);
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
