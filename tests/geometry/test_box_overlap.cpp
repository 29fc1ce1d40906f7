// The oriented-box overlap (include/manisoft/geometry/box_overlap.hpp) on hand-computed cases:
// two unit cubes apart along an axis (overlapping, touching, separated, and separated but within
// a margin), and two cubes turned 45 degrees whose only separating axis is the cross product of
// two edge directions.
#include <catch2/catch.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <numbers>

#include "manisoft/geometry/box_overlap.hpp"

namespace {

using manisoft::geometry::boxes_overlap;
using Pose = manisoft::math::Pose<double>;
using Eigen::Vector3d;

const Vector3d half = Vector3d::Constant(0.5);  // a unit cube

Pose at(const Vector3d& t, const Eigen::Matrix3d& r = Eigen::Matrix3d::Identity()) { return Pose{r, t}; }

bool cubes_overlap(const Pose& a, const Pose& b, double margin = 0) {
  return boxes_overlap(a, Vector3d::Zero(), half, b, Vector3d::Zero(), half, margin);
}

}  // namespace

TEST_CASE("box overlap: unit cubes apart along an axis", "[geometry]") {
  const Pose a = at(Vector3d::Zero());
  // centres 0.9 apart: the faces interpenetrate by 0.1
  CHECK(cubes_overlap(a, at(Vector3d(0.9, 0, 0))));
  // centres 1.0 apart: the faces touch (half extents 0.5 + 0.5), which counts as overlapping
  CHECK(cubes_overlap(a, at(Vector3d(0, 1.0, 0))));
  // centres 1.2 apart: a gap of 0.2 along z
  CHECK_FALSE(cubes_overlap(a, at(Vector3d(0, 0, 1.2))));
  CHECK_FALSE(cubes_overlap(at(Vector3d(0, 0, 1.2)), a));
  // the same gap against a margin: 0.3 > 0.2 overlaps, 0.1 < 0.2 does not
  CHECK(cubes_overlap(a, at(Vector3d(0, 0, 1.2)), 0.3));
  CHECK_FALSE(cubes_overlap(a, at(Vector3d(0, 0, 1.2)), 0.1));
  // the box centre is given in its frame: frame at x = 0.5, centre 0.7 further: 1.2 from a
  CHECK_FALSE(boxes_overlap(a, Vector3d::Zero(), half, at(Vector3d(0.5, 0, 0)), Vector3d(0.7, 0, 0), half, 0.0));
  CHECK(boxes_overlap(a, Vector3d::Zero(), half, at(Vector3d(0.5, 0, 0)), Vector3d(0.4, 0, 0), half, 0.0));
}

TEST_CASE("box overlap: crossed edges separated only by their cross product", "[geometry]") {
  // Cube a turned 45 degrees about x: its top edge runs along x at height sqrt(2)/2. Cube b
  // turned 45 degrees about y, centre at height h: its bottom edge runs along y at h - sqrt(2)/2.
  // The edges cross one above the other; the gap between them is h - sqrt(2) along z = x cross y,
  // which is a face normal of neither cube. On the face normals the projections overlap while
  // sqrt(2)/2 h <= 0.5 + 0.5 (0.5 + sqrt(2)/2 + 0.5), i.e. for h <= 1.914.
  const double q = std::numbers::pi / 4;
  const Pose a = at(Vector3d::Zero(), Eigen::AngleAxisd(q, Vector3d::UnitX()).toRotationMatrix());
  const Eigen::Matrix3d rb = Eigen::AngleAxisd(q, Vector3d::UnitY()).toRotationMatrix();
  // h = 1.6: a gap of 0.186 between the edges, found only on the cross-product axis
  CHECK_FALSE(cubes_overlap(a, at(Vector3d(0, 0, 1.6), rb)));
  // h = 1.3: the edges interpenetrate by 0.114
  CHECK(cubes_overlap(a, at(Vector3d(0, 0, 1.3), rb)));
  // h = 1.6 with a margin of 0.3: each cube grown by 0.15 (its edge 0.15 sqrt(2) = 0.212 nearer)
  CHECK(cubes_overlap(a, at(Vector3d(0, 0, 1.6), rb), 0.3));
  // h = 2.0: beyond 1.914, separated on a face normal as well
  CHECK_FALSE(cubes_overlap(a, at(Vector3d(0, 0, 2.0), rb)));
}
