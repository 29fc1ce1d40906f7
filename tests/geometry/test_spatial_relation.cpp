// The ARR relations behind, next to and between at the edges of their margins
// (include/manisoft/geometry/spatial_relation.hpp): hand-placed centres 1 mm inside and 1 mm
// outside each margin of the default RelationTolerances, the expected answers worked out by hand
// from the documented definitions (the viewer looks from +x: behind is -x).
#include <catch2/catch.hpp>

#include <Eigen/Core>

#include <array>
#include <cmath>

#include "manisoft/geometry/spatial_relation.hpp"

namespace {

using manisoft::geometry::RelationKind;
using Eigen::Vector2d;

constexpr double mm = 1e-3;

bool holds(RelationKind kind, Vector2d subject, Vector2d b) {
  const std::array<Vector2d, 2> c{subject, b};
  return manisoft::geometry::relation_holds(kind, c);
}

bool holds(RelationKind kind, Vector2d subject, Vector2d b, Vector2d c) {
  const std::array<Vector2d, 3> centres{subject, b, c};
  return manisoft::geometry::relation_holds(kind, centres);
}

}  // namespace

TEST_CASE("behind: 5 to 30 cm further from the viewer (-x), at most 8 cm across", "[geometry][relation]") {
  const Vector2d b(0.50, 0.10);
  // along -x: 5 cm and 30 cm are the edges
  CHECK(holds(RelationKind::behind, b + Vector2d(-0.050 - mm, 0), b));
  CHECK_FALSE(holds(RelationKind::behind, b + Vector2d(-0.050 + mm, 0), b));
  CHECK(holds(RelationKind::behind, b + Vector2d(-0.300 + mm, 0), b));
  CHECK_FALSE(holds(RelationKind::behind, b + Vector2d(-0.300 - mm, 0), b));
  // across (y, either side): 8 cm is the edge
  CHECK(holds(RelationKind::behind, b + Vector2d(-0.15, 0.080 - mm), b));
  CHECK_FALSE(holds(RelationKind::behind, b + Vector2d(-0.15, 0.080 + mm), b));
  CHECK(holds(RelationKind::behind, b + Vector2d(-0.15, -0.080 + mm), b));
  CHECK_FALSE(holds(RelationKind::behind, b + Vector2d(-0.15, -0.080 - mm), b));
  // in front of the reference (+x) is not behind it; the reference is then behind the subject
  CHECK_FALSE(holds(RelationKind::behind, b + Vector2d(0.15, 0), b));
  CHECK(holds(RelationKind::behind, b, b + Vector2d(0.15, 0)));
  // tightened by 2 cm: 7 to 28 cm along, 6 cm across
  const auto tight = manisoft::geometry::RelationTolerances{}.tightened(0.02);
  const auto tight_holds = [&](Vector2d subject) {
    const std::array<Vector2d, 2> c{subject, b};
    return manisoft::geometry::relation_holds(RelationKind::behind, c, tight);
  };
  CHECK(tight_holds(b + Vector2d(-0.070 - mm, 0.060 - mm)));
  CHECK_FALSE(tight_holds(b + Vector2d(-0.070 + mm, 0)));
  CHECK_FALSE(tight_holds(b + Vector2d(-0.280 - mm, 0)));
  CHECK_FALSE(tight_holds(b + Vector2d(-0.15, 0.060 + mm)));
}

TEST_CASE("next to: centres at most 20 cm apart, in any direction", "[geometry][relation]") {
  const Vector2d b(0.45, -0.05);
  // a 3-4-5 direction: offset r (0.6, 0.8) is r apart
  for (const Vector2d& dir : {Vector2d(0.6, 0.8), Vector2d(-0.8, 0.6), Vector2d(0.0, -1.0), Vector2d(-1.0, 0.0)}) {
    CAPTURE(dir.transpose());
    CHECK(holds(RelationKind::next_to, b + (0.200 - mm) * dir, b));
    CHECK_FALSE(holds(RelationKind::next_to, b + (0.200 + mm) * dir, b));
  }
  CHECK(holds(RelationKind::next_to, b + Vector2d(0.1194, 0.1592), b));      // 0.199 m apart
  CHECK_FALSE(holds(RelationKind::next_to, b + Vector2d(0.1206, 0.1608), b));  // 0.201 m apart
  CHECK(holds(RelationKind::next_to, b, b));                                  // same centre: 0 m
}

TEST_CASE("between: on the middle half of the references' segment, at most 5 cm off it", "[geometry][relation]") {
  // references 40 cm apart along y: t = (y + 0.10) / 0.40 must lie in [0.25, 0.75], |x - 0.40| <= 0.05
  const Vector2d b(0.40, -0.10), c(0.40, 0.30);
  CHECK(holds(RelationKind::between, Vector2d(0.40, 0.000 + mm), b, c));  // t = 0.2525
  CHECK_FALSE(holds(RelationKind::between, Vector2d(0.40, 0.000 - mm), b, c));  // t = 0.2475
  CHECK(holds(RelationKind::between, Vector2d(0.40, 0.200 - mm), b, c));  // t = 0.7475
  CHECK_FALSE(holds(RelationKind::between, Vector2d(0.40, 0.200 + mm), b, c));  // t = 0.7525
  CHECK(holds(RelationKind::between, Vector2d(0.450 - mm, 0.10), b, c));
  CHECK_FALSE(holds(RelationKind::between, Vector2d(0.450 + mm, 0.10), b, c));
  CHECK(holds(RelationKind::between, Vector2d(0.350 + mm, 0.10), b, c));
  CHECK_FALSE(holds(RelationKind::between, Vector2d(0.350 - mm, 0.10), b, c));
  // the references' order does not matter (t becomes 1 - t)
  CHECK(holds(RelationKind::between, Vector2d(0.40, 0.000 + mm), c, b));
  CHECK_FALSE(holds(RelationKind::between, Vector2d(0.40, 0.000 - mm), c, b));
  // a slanted segment: (0.30, 0) to (0.60, 0.40), 0.5 m long along (0.6, 0.8), normal (-0.8, 0.6)
  const Vector2d p(0.30, 0.0), q(0.60, 0.40), mid(0.45, 0.20), normal(-0.8, 0.6), along(0.6, 0.8);
  CHECK(holds(RelationKind::between, mid + (0.050 - mm) * normal, p, q));
  CHECK_FALSE(holds(RelationKind::between, mid + (0.050 + mm) * normal, p, q));
  CHECK(holds(RelationKind::between, mid - (0.050 - mm) * normal, p, q));
  CHECK_FALSE(holds(RelationKind::between, mid - (0.050 + mm) * normal, p, q));
  CHECK(holds(RelationKind::between, mid + (0.125 - mm) * along, p, q));   // t = 0.748
  CHECK_FALSE(holds(RelationKind::between, mid + (0.125 + mm) * along, p, q));  // t = 0.752
  // coincident references have no segment: never between
  CHECK_FALSE(holds(RelationKind::between, b, b, b));
  CHECK_FALSE(holds(RelationKind::between, Vector2d(0.41, 0.0), b, b));
}
