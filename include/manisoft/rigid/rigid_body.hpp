// Rigid bodies, split like Pinocchio's Model/Data: RigidBodyDesc is what a user gives (shape,
// density or mass, pose, velocities, friction, restitution, static flag); RigidBodyModel is the
// immutable data derived from it (mass, inertia about the centre of mass, centre-of-mass offset);
// RigidBodyState is what a step changes (centre-of-mass position, unit quaternion, linear and
// angular velocity in the world frame, accumulated external force and torque).
// Newton-Euler: m dv/dt = f, I_w dw/dt = tau - w x I_w w (gyroscopic term integrated implicitly).
#pragma once

#include "manisoft/core/error.hpp"
#include "manisoft/geometry/mass_properties.hpp"

#include <Eigen/Dense>

#include <optional>
#include <string>

namespace manisoft::rigid {

using BodyId = std::uint32_t;

/// Everything needed to create a body.
struct RigidBodyDesc {
  geometry::Shape<double> shape{geometry::Box<double>{}};
  double density{0};  ///< kg/m^3; used when `mass` is 0
  double mass{0};     ///< kg; when > 0 overrides the density (inertia scaled to match)
  std::optional<Eigen::Matrix3d> inertia;  ///< kg m^2 about the centre of mass, shape axes (optional)
  Eigen::Vector3d position{Eigen::Vector3d::Zero()};  ///< of the shape frame origin, world
  Eigen::Quaterniond orientation{Eigen::Quaterniond::Identity()};
  Eigen::Vector3d linear_velocity{Eigen::Vector3d::Zero()};   ///< of the centre of mass, world
  Eigen::Vector3d angular_velocity{Eigen::Vector3d::Zero()};  ///< world
  double friction{0.5};     ///< Coulomb coefficient (pairs use the geometric mean)
  double restitution{0.0};  ///< 0..1 (pairs use the larger)
  /// Rolling resistance length, m: the contact resists rolling with a torque of at most this
  /// times the normal force (pairs use the larger; 0: none). See contact_solver.hpp.
  double rolling_resistance{0.0};
  bool is_static{false};
  std::string name;
};

/// Immutable data of one body.
struct RigidBodyModel {
  std::string name;
  bool is_static{false};
  double mass{0}, inverse_mass{0};
  Eigen::Matrix3d inertia{Eigen::Matrix3d::Zero()};          ///< about the COM, body axes
  Eigen::Matrix3d inverse_inertia{Eigen::Matrix3d::Zero()};  ///< zero for static bodies
  Eigen::Vector3d center_of_mass{Eigen::Vector3d::Zero()};   ///< in the shape frame
  double friction{0.5}, restitution{0}, rolling_resistance{0};
  std::uint32_t first_geom{0}, geom_count{0};
  double bounding_radius{0};  ///< of all geometry about the COM
};

/// Mutable state of one body. Plain data (copied to roll back a failed step).
struct RigidBodyState {
  Eigen::Vector3d position{Eigen::Vector3d::Zero()};  ///< centre of mass, world
  Eigen::Quaterniond orientation{Eigen::Quaterniond::Identity()};
  Eigen::Matrix3d rotation{Eigen::Matrix3d::Identity()};  ///< of `orientation`, cached
  Eigen::Vector3d linear_velocity{Eigen::Vector3d::Zero()};
  Eigen::Vector3d angular_velocity{Eigen::Vector3d::Zero()};
  Eigen::Vector3d force{Eigen::Vector3d::Zero()};   ///< external, world, applied at the COM this step
  Eigen::Vector3d torque{Eigen::Vector3d::Zero()};  ///< external, world, this step
  double travel{0};      ///< bound on the distance any point of the body has moved (contact cache)
  double sleep_time{0};  ///< how long the body has been nearly still
  bool awake{true};
};

/// Refuses shapes with non-positive or non-finite sizes; `who` names the body.
inline void validate_shape(const geometry::Shape<double>& shape, const std::string& who) {
  auto check = [&](const geometry::PrimitiveShape<double>& prim) {
    std::visit(
        [&](const auto& s) {
          using S = std::decay_t<decltype(s)>;
          if constexpr (std::is_same_v<S, geometry::Box<double>>) {
            for (int i = 0; i < 3; ++i) manisoft::detail::require_positive((who + ": box half extent").c_str(), s.half_extents[i]);
          } else if constexpr (std::is_same_v<S, geometry::Sphere<double>>) {
            manisoft::detail::require_positive((who + ": sphere radius").c_str(), s.radius);
          } else if constexpr (std::is_same_v<S, geometry::Capsule<double>>) {
            manisoft::detail::require_positive((who + ": capsule radius").c_str(), s.radius);
            manisoft::detail::require_non_negative((who + ": capsule half_length").c_str(), s.half_length);
          } else if constexpr (std::is_same_v<S, geometry::Cylinder<double>>) {
            manisoft::detail::require_positive((who + ": cylinder radius").c_str(), s.radius);
            manisoft::detail::require_positive((who + ": cylinder half_height").c_str(), s.half_height);
          } else {
            for (const auto& v : s.vertices) {
              if (!v.allFinite()) manisoft::detail::fail(who, ": convex mesh '", s.source, "' has a non-finite vertex");
            }
          }
        },
        prim);
  };
  std::visit(
      [&](const auto& s) {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, geometry::Compound<double>>) {
          if (s.parts.empty()) manisoft::detail::fail(who, ": compound shape has no parts");
          for (const auto& part : s.parts) {
            if (!part.position.allFinite() || !part.orientation.coeffs().allFinite() || part.orientation.norm() < 1e-9) {
              manisoft::detail::fail(who, ": compound part pose is not finite");
            }
            check(part.shape);
          }
        } else {
          check(geometry::PrimitiveShape<double>(s));
        }
      },
      shape);
}

/// Derives the model of a body from its description; `id` is used in error messages.
inline RigidBodyModel make_body_model(const RigidBodyDesc& desc, BodyId id) {
  RigidBodyModel m;
  m.name = desc.name;
  m.is_static = desc.is_static;
  auto who = [&]() { return "rigid body " + std::to_string(id) + (desc.name.empty() ? "" : " ('" + desc.name + "')"); };
  if (!std::isfinite(desc.friction) || desc.friction < 0) manisoft::detail::fail(who(), ": friction = ", desc.friction, " must be finite and >= 0");
  if (!std::isfinite(desc.restitution) || desc.restitution < 0 || desc.restitution > 1) {
    manisoft::detail::fail(who(), ": restitution = ", desc.restitution, " must be in [0, 1]");
  }
  if (!std::isfinite(desc.rolling_resistance) || desc.rolling_resistance < 0) {
    manisoft::detail::fail(who(), ": rolling_resistance = ", desc.rolling_resistance, " m must be finite and >= 0");
  }
  if (!desc.position.allFinite() || !desc.linear_velocity.allFinite() || !desc.angular_velocity.allFinite() ||
      !desc.orientation.coeffs().allFinite() || desc.orientation.norm() < 1e-9) {
    manisoft::detail::fail(who(), ": position, orientation and velocities must be finite (and the quaternion non-zero)");
  }
  validate_shape(desc.shape, who());
  m.friction = desc.friction;
  m.restitution = desc.restitution;
  m.rolling_resistance = desc.rolling_resistance;
  if (desc.is_static) {
    // Mass properties only for the centre of mass (to place the geometry); density may be 0.
    m.center_of_mass = geometry::mass_properties(desc.shape, 1.0).center_of_mass;
    return m;
  }
  if (desc.mass > 0) {
    manisoft::detail::require_positive((who() + ": mass").c_str(), desc.mass);
  } else {
    if (!(desc.density > 0) || !std::isfinite(desc.density)) {
      manisoft::detail::fail(who(), ": a dynamic body needs density > 0 or mass > 0 (density = ", desc.density,
                   ", mass = ", desc.mass, ")");
    }
  }
  geometry::MassProperties<double> mp = geometry::mass_properties(desc.shape, desc.mass > 0 ? 1.0 : desc.density);
  if (desc.mass > 0) mp = mp.scaled(desc.mass / mp.mass);
  if (desc.inertia) {
    if (!desc.inertia->allFinite()) manisoft::detail::fail(who(), ": inertia has non-finite entries");
    mp.inertia = *desc.inertia;
  }
  m.mass = mp.mass;
  m.center_of_mass = mp.center_of_mass;
  m.inertia = 0.5 * (mp.inertia + mp.inertia.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m.inertia);
  if (!(m.mass > 0) || !std::isfinite(m.mass) || !(eig.eigenvalues().minCoeff() > 0)) {
    manisoft::detail::fail(who(), ": mass ", m.mass, " and inertia eigenvalues (", eig.eigenvalues().transpose(),
                 ") must be positive");
  }
  m.inverse_mass = 1.0 / m.mass;
  m.inverse_inertia = m.inertia.inverse();
  return m;
}

}  // namespace manisoft::rigid
