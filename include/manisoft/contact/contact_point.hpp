// Geometric contact output of the narrow phase: up to four points per shape pair, each with a
// world position, a unit normal pointing from shape A to shape B and a signed separation
// (negative = penetration depth). Points with separation up to the contact margin are reported
// (speculative contacts), so a solver can stop approaching bodies before they touch.
#pragma once

#include <Eigen/Core>

#include "manisoft/math/se3.hpp"

#include <array>
#include <cstdint>

namespace manisoft::contact {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// Rigid placement of a shape in the world: x_world = rotation * x_local + translation.
using Pose = math::Pose<double>;

/// Most points a single shape pair reports (box-box face contact after reduction has 4).
inline constexpr int kMaxContactPoints = 4;

/// Which shape the normal is attached to: a face normal belongs to the shape that owns the face,
/// so it rotates with that body when a cached contact is extrapolated.
enum class NormalOwner : std::uint8_t { shape_a, shape_b };

struct ContactPoint {
  Vec3 position{Vec3::Zero()};  ///< world, midway between the two surfaces
  double separation{0};         ///< signed gap along normal; < 0 = penetration
};

/// The geometric contacts of one shape pair.
struct ContactSet {
  Vec3 normal{Vec3::UnitZ()};  ///< world, unit, from A to B (shared by all points)
  NormalOwner normal_owner{NormalOwner::shape_a};
  int count{0};
  std::array<ContactPoint, kMaxContactPoints> points{};
  /// The touching points are not fixed material points (a curved surface or an edge carries the
  /// contact): a cached manifold would drift as the bodies roll, so re-detect it every step.
  bool rolling{false};

  void clear() {
    count = 0;
    rolling = false;
  }
  void add(const Vec3& position, double separation) {
    if (count < kMaxContactPoints) points[static_cast<std::size_t>(count++)] = {position, separation};
  }
};

}  // namespace manisoft::contact
