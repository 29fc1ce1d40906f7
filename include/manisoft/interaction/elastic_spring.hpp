// Elastic spring coupling between the rod tip frame and a rigid end-effector (paper, section 3.1,
// eq. "F = -kF dx, M = -kM dtheta"): a zero-rest-length translational and rotational spring,
//   force on the body   F = -kF (x_b - x_t) - cF (v_b - v_t)
//   torque on the body  M = -kM R_t Log(R_t^T R_b) - cM (w_b - w_t)        (lab frame)
// applied equal and opposite to the rod tip (force on the last node, torque on the last element
// turned into its material frame). x_t, R_t: last node and last element's frame (R_t = Q^T);
// x_b, R_b: the body's attachment frame. Without damping F is central (along x_b - x_t), so the
// pair conserves linear and angular momentum; the damping terms conserve linear momentum only.
//
// Presets. The paper prints kF = 0.1 N/m and kM = 10 N m/rad (`paper()`): under gravity a 0.2 kg
// gripper would hang m g / kF = 19.6 m below the tip, i.e. it does not hold an end-effector.
// `stiff()` holds the gripper (0.2 kg) plus a 0.5 kg object at m g / kF = 0.34 mm and, on a 5 cm
// lever, 0.34 N m / kM = 0.2 degrees, explicit-stable at dt = 2e-4 s: the stiffest translational
// mode (kF against the tip node, 0.196 kg, in series with the gripper) has omega dt = 0.09, the
// rotational one (kM against the tip element's bending inertia, 2.5e-4 kg m^2) omega dt = 0.13.
// `arm()`, the arm world's default, is stiff() with kM = 1000 N m/rad (omega dt = 0.4) and
// cM = 0.6 N m s/rad: the executor drives the tip element with up to 150 N m, and a gripper
// carrying a load must follow the tip's rotation closely.
#pragma once

#include <Eigen/Core>

#include "manisoft/core/error.hpp"
#include "manisoft/math/so3.hpp"

namespace manisoft::interaction {

struct ElasticSpringParameters {
  double translational_stiffness = 2e4;  ///< kF [N/m]
  double rotational_stiffness = 100;     ///< kM [N m/rad]
  double translational_damping = 25;     ///< cF [N s/m]
  double rotational_damping = 0.3;       ///< cM [N m s/rad]

  /// The values printed in the paper's parameter table (they cannot carry a gripper's weight).
  static ElasticSpringParameters paper() { return {0.1, 10, 0, 0}; }
  /// Separation < 1 mm and < 1 degree at 0.7 kg (see the header comment).
  static ElasticSpringParameters stiff() { return {}; }
  /// The arm world's default: stiff() with a 10x stiffer, more damped rotational spring.
  static ElasticSpringParameters arm() { return {2e4, 1000, 25, 0.6}; }

  void validate() const {
    manisoft::detail::require_positive("ElasticSpring translational_stiffness", translational_stiffness);
    manisoft::detail::require_positive("ElasticSpring rotational_stiffness", rotational_stiffness);
    manisoft::detail::require_non_negative("ElasticSpring translational_damping", translational_damping);
    manisoft::detail::require_non_negative("ElasticSpring rotational_damping", rotational_damping);
  }
};

/// Pose and velocity of one side of the spring (lab frame).
struct SpringFrame {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< columns: frame axes in the lab
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< lab frame
};

/// Wrench on the body; the rod tip receives (-force, -torque) at its node and element.
struct SpringWrench {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   ///< on the body, at its attachment point [N]
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();  ///< on the body, lab frame [N m]
  Eigen::Vector3d separation = Eigen::Vector3d::Zero();  ///< x_b - x_t [m]
  Eigen::Vector3d rotation_error = Eigen::Vector3d::Zero();  ///< R_t Log(R_t^T R_b), lab [rad]
  double energy = 0;  ///< kF |dx|^2 / 2 + kM |dtheta|^2 / 2 [J]
};

class ElasticSpring {
 public:
  ElasticSpring() = default;
  explicit ElasticSpring(const ElasticSpringParameters& p) : params_(p) { params_.validate(); }

  const ElasticSpringParameters& parameters() const { return params_; }

  SpringWrench wrench(const SpringFrame& tip, const SpringFrame& body) const {
    SpringWrench w;
    w.separation = body.position - tip.position;
    w.rotation_error = tip.rotation * math::so3::log(Eigen::Matrix3d(tip.rotation.transpose() * body.rotation));
    w.force = -params_.translational_stiffness * w.separation -
              params_.translational_damping * (body.linear_velocity - tip.linear_velocity);
    w.torque = -params_.rotational_stiffness * w.rotation_error -
               params_.rotational_damping * (body.angular_velocity - tip.angular_velocity);
    w.energy = 0.5 * params_.translational_stiffness * w.separation.squaredNorm() +
               0.5 * params_.rotational_stiffness * w.rotation_error.squaredNorm();
    return w;
  }

 private:
  ElasticSpringParameters params_;
};

}  // namespace manisoft::interaction
