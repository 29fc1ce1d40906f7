// The SE(3) pose distance of the paper, section 3.4:
//   [d_p, d_r] = log(P^-1 P_hat),   d = |d_p| + alpha |d_r|,
// and the executor success criterion of the appendix (d_p < 0.03 m and d_r < 0.3 rad).
//
// Two position errors exist and are easy to confuse:
//   - position_error = |d_p|, the translational part of the SE(3) logarithm, d_p = V^-1(d_r) t
//     with t = R^T (p_hat - p) (see math/se3.hpp). It is the length of the screw motion that
//     carries P onto P_hat and is what the paper's d and success criterion use. It grows with
//     the rotation error: a quarter turn with a 1 m offset gives |d_p| = pi sqrt(2)/4 = 1.11 m.
//   - euclidean_position_error = |p - p_hat|, the straight-line distance between the origins.
// The two agree when the orientations agree. rotation_error = |d_r| is the geodesic angle between
// the orientations, in [0, pi]. d mixes metres and radians: alpha is in m/rad.
#pragma once

#include <type_traits>

#include "manisoft/core/error.hpp"
#include "manisoft/math/se3.hpp"

namespace manisoft::reward {

template <typename Scalar>
struct PoseError {
  Scalar position_error;            ///< |d_p| of log(P^-1 P_hat), m (the paper's d_p)
  Scalar rotation_error;            ///< |d_r|, geodesic angle, rad, in [0, pi] (the paper's d_r)
  Scalar distance;                  ///< d = |d_p| + alpha |d_r|
  Scalar euclidean_position_error;  ///< |p - p_hat|, m
};

/// The twist [d_p; d_r] = log(P^-1 P_hat), expressed in the current end-effector frame.
template <typename Scalar>
math::Vector6<Scalar> pose_difference(const math::Pose<Scalar>& current, const math::Pose<Scalar>& target) {
  return math::se3::log(current.inverse() * target);
}

/// Errors between the current pose P and the target pose P_hat. alpha (m/rad, > 0) weighs the
/// rotation in d; the paper's best value is 0.2.
template <typename Scalar>
PoseError<Scalar> pose_error(const math::Pose<Scalar>& current, const math::Pose<Scalar>& target,
                             std::type_identity_t<Scalar> alpha = Scalar(0.2)) {
  manisoft::detail::require_positive("pose distance alpha", alpha);
  const math::Vector6<Scalar> twist = pose_difference(current, target);
  const Scalar position = twist.template head<3>().norm();
  const Scalar rotation = twist.template tail<3>().norm();
  return {position, rotation, position + alpha * rotation, (target.translation - current.translation).norm()};
}

/// Tolerances of the executor success criterion (paper appendix): d_p < 0.03 m, d_r < 0.3 rad.
template <typename Scalar>
struct SuccessTolerance {
  Scalar position = Scalar(0.03);  ///< m, compared with PoseError::position_error (|d_p|)
  Scalar rotation = Scalar(0.3);   ///< rad, compared with PoseError::rotation_error (|d_r|)
};

/// The benchmark's success test: |d_p| < tolerance.position and |d_r| < tolerance.rotation,
/// with d_p from the SE(3) logarithm as in the paper. For a straight-line position test compare
/// error.euclidean_position_error yourself.
template <typename Scalar>
bool is_success(const PoseError<Scalar>& error, const SuccessTolerance<Scalar>& tolerance = {}) {
  return error.position_error < tolerance.position && error.rotation_error < tolerance.rotation;
}

}  // namespace manisoft::reward
