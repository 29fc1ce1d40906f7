// True cylinder contact: the narrow-phase pairs against hand-computed depths and normals (cylinder
// on a box face standing, lying and tilted on its rim; against a box edge, a convex mesh, a
// capsule), GJK/EPA against analytic distances (sphere against a cylinder's side, cap and rim,
// crossed cylinders), and the dynamics they give: a cylinder rolls down an incline at
// a = 2/3 g sin(t) (solid cylinder, I = m r^2 / 2, no slip), slides and spins at
// a = g (sin t - mu cos t), alpha = 2 mu g cos t / r when friction cannot hold it, rests standing
// and lying without drift, sinking or popping up, and steps without heap allocation.
#include "../../benchmarks/rigid_scenes.hpp"
#include "../support/allocation_counter.hpp"

#include "manisoft/contact/narrow_phase.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <cmath>
#include <numbers>
#include <random>

namespace test_curved_contact {  // per-file namespace: the group's tests build as one unity translation unit

using namespace manisoft;
using Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

namespace {

constexpr double kDt = 2e-4;
constexpr double kR = 0.03, kH = 0.06;  // the can of the brief: radius 3 cm, half height 6 cm

contact::CollisionShape cylinder_shape(double r = kR, double h = kH) {
  return contact::make_collision_shape(geometry::Cylinder<double>{r, h});
}
contact::CollisionShape box_shape(const Vector3d& half) { return contact::make_collision_shape(geometry::Box<double>{half}); }

contact::Pose pose(const Vector3d& t, const Quat& q = Quat::Identity()) {
  contact::Pose p;
  p.translation = t;
  p.rotation = q.toRotationMatrix();
  return p;
}

/// A big box whose top face is the plane z = 0.
const Vector3d kSlabHalf(0.5, 0.5, 0.1);
contact::Pose slab_pose() { return pose({0, 0, -0.1}); }

Quat about_y(double angle) { return Quat(Eigen::AngleAxisd(angle, Vector3d::UnitY())); }
Quat about_x(double angle) { return Quat(Eigen::AngleAxisd(angle, Vector3d::UnitX())); }

contact::ConvexDistance distance(const contact::CollisionShape& a, const contact::Pose& pa, const contact::CollisionShape& b,
                                 const contact::Pose& pb) {
  contact::ConvexDistance d;
  REQUIRE(contact::convex_distance(contact::ConvexSupport{&a, pa}, contact::ConvexSupport{&b, pb}, 1.0, d));
  return d;
}

}  // namespace

TEST_CASE("cylinder on a box face: standing, lying and tilted on its rim", "[world][contact][cylinder]") {
  const auto cyl = cylinder_shape();
  const auto slab = box_shape(kSlabHalf);
  contact::ContactSet c;
  contact::NarrowPhaseScratch scratch;
  SECTION("lying on its side 1 mm deep: two points at the ends of the contact line") {
    const auto cp = pose({0.01, 0.02, kR - 1e-3}, about_y(std::numbers::pi / 2));  // axis along x
    REQUIRE(contact::collide(cyl, cp, slab, slab_pose(), 0.002, c, scratch));
    REQUIRE(c.count == 2);
    CHECK((c.normal - Vector3d(0, 0, -1)).norm() < 1e-12);  // from the cylinder into the box
    CHECK(c.rolling);
    std::array<double, 2> xs{};
    for (int k = 0; k < 2; ++k) {
      const auto& p = c.points[static_cast<std::size_t>(k)];
      CHECK(p.separation == Approx(-1e-3).margin(1e-12));
      CHECK(p.position.z() == Approx(-0.5e-3).margin(1e-12));  // midway between the surfaces
      CHECK(p.position.y() == Approx(0.02).margin(1e-12));
      xs[static_cast<std::size_t>(k)] = p.position.x();
    }
    std::sort(xs.begin(), xs.end());
    CHECK(xs[0] == Approx(0.01 - kH).margin(1e-12));
    CHECK(xs[1] == Approx(0.01 + kH).margin(1e-12));
    // Same pair the other way round: the normal flips, the points do not move.
    REQUIRE(contact::collide(slab, slab_pose(), cyl, cp, 0.002, c, scratch));
    REQUIRE(c.count == 2);
    CHECK((c.normal - Vector3d(0, 0, 1)).norm() < 1e-12);
    CHECK(c.points[0].separation == Approx(-1e-3).margin(1e-12));
  }
  SECTION("lying across the edge of a box: the contact line is clipped at the edge") {
    const auto cp = pose({0.5, 0, kR - 1e-3}, about_y(std::numbers::pi / 2));  // centred on the x = 0.5 edge
    REQUIRE(contact::collide(cyl, cp, slab, slab_pose(), 0.002, c, scratch));
    REQUIRE(c.count == 2);
    double lo = 1, hi = -1;
    for (int k = 0; k < 2; ++k) {
      CHECK(c.points[static_cast<std::size_t>(k)].separation == Approx(-1e-3).margin(1e-12));
      lo = std::min(lo, c.points[static_cast<std::size_t>(k)].position.x());
      hi = std::max(hi, c.points[static_cast<std::size_t>(k)].position.x());
    }
    CHECK(lo == Approx(0.5 - kH).margin(1e-12));
    CHECK(hi == Approx(0.5).margin(1e-12));
  }
  SECTION("standing on its cap 0.5 mm deep: four rim points, not rocking") {
    const auto cp = pose({0.1, -0.1, kH - 0.5e-3});
    REQUIRE(contact::collide(cyl, cp, slab, slab_pose(), 0.002, c, scratch));
    REQUIRE(c.count == 4);
    CHECK_FALSE(c.rolling);
    CHECK((c.normal - Vector3d(0, 0, -1)).norm() < 1e-12);
    Vector3d centroid = Vector3d::Zero();
    for (int k = 0; k < 4; ++k) {
      const auto& p = c.points[static_cast<std::size_t>(k)];
      CHECK(p.separation == Approx(-0.5e-3).margin(1e-12));
      CHECK(std::hypot(p.position.x() - 0.1, p.position.y() + 0.1) == Approx(kR).margin(1e-12));  // on the rim
      centroid += p.position / 4;
    }
    // The points span the cap: their centroid is within a third of the radius of the axis.
    CHECK(std::hypot(centroid.x() - 0.1, centroid.y() + 0.1) < kR / 3);
  }
  SECTION("tilted 30 degrees on its rim: one point, the lowest rim point") {
    const double t = std::numbers::pi / 6;
    // Lowest point of the rim: c - h a - r u, a = (sin t, 0, cos t), u = (-cos t, 0, sin t).
    const double below = kH * std::cos(t) + kR * std::sin(t);
    const auto cp = pose({0, 0, below - 1e-3}, about_y(t));
    REQUIRE(contact::collide(cyl, cp, slab, slab_pose(), 0.002, c, scratch));
    REQUIRE(c.count == 1);
    CHECK(c.rolling);
    CHECK(c.points[0].separation == Approx(-1e-3).margin(1e-12));
    CHECK(c.points[0].position.x() == Approx(-kH * std::sin(t) + kR * std::cos(t)).margin(1e-12));
    CHECK(c.points[0].position.y() == Approx(0.0).margin(1e-12));
    CHECK((c.normal - Vector3d(0, 0, -1)).norm() < 1e-12);
  }
  SECTION("farther than the margin: nothing") {
    CHECK_FALSE(contact::collide(cyl, pose({0, 0, kH + 0.0021}), slab, slab_pose(), 0.002, c, scratch));
    REQUIRE(contact::collide(cyl, pose({0, 0, kH + 0.0015}), slab, slab_pose(), 0.002, c, scratch));
    CHECK(c.points[0].separation == Approx(0.0015).margin(1e-12));  // speculative contact
  }
}

TEST_CASE("cylinder against a box edge, a convex mesh and a capsule (GJK/EPA + feature clipping)", "[world][contact][cylinder]") {
  const auto cyl = cylinder_shape();
  contact::ContactSet c;
  contact::NarrowPhaseScratch scratch;
  SECTION("standing against a vertical box edge 1 mm deep: normal along the edge's bisector") {
    const auto box = box_shape(Vector3d(0.05, 0.05, 0.05));
    const auto bp = pose(Vector3d::Zero(), Quat(Eigen::AngleAxisd(std::numbers::pi / 4, Vector3d::UnitZ())));
    const double edge = 0.05 * std::sqrt(2.0);  // the box's vertical edge at x = 0.0707, y = 0
    const auto cp = pose({edge + kR - 1e-3, 0, 0});
    REQUIRE(contact::collide(box, bp, cyl, cp, 0.002, c, scratch));
    REQUIRE(c.count >= 1);
    CHECK((c.normal - Vector3d(1, 0, 0)).norm() < 1e-4);  // EPA against a curved side
    double deepest = 1;
    for (int k = 0; k < c.count; ++k) deepest = std::min(deepest, c.points[static_cast<std::size_t>(k)].separation);
    CHECK(deepest == Approx(-1e-3).margin(1e-7));
    for (int k = 0; k < c.count; ++k) {
      CHECK(std::abs(c.points[static_cast<std::size_t>(k)].position.y()) < 1e-6);
      CHECK(std::abs(c.points[static_cast<std::size_t>(k)].position.z()) <= 0.05 + 1e-9);
    }
  }
  SECTION("standing on a convex mesh slab 0.5 mm deep: a rim polygon at the right depth") {
    geometry::ConvexMesh<double> mesh;
    for (int k = 0; k < 8; ++k) mesh.vertices.emplace_back(k & 1 ? 0.2 : -0.2, k & 2 ? 0.2 : -0.2, k & 4 ? 0.0 : -0.05);
    mesh.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                      {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    mesh.source = "slab";
    const auto slab = contact::make_collision_shape(geometry::PrimitiveShape<double>(mesh));
    REQUIRE(contact::collide(slab, pose(Vector3d::Zero()), cyl, pose({0.05, 0, kH - 0.5e-3}), 0.002, c, scratch));
    REQUIRE(c.count >= 3);
    CHECK((c.normal - Vector3d(0, 0, 1)).norm() < 1e-6);
    for (int k = 0; k < c.count; ++k) {
      CHECK(c.points[static_cast<std::size_t>(k)].separation == Approx(-0.5e-3).margin(1e-7));
      CHECK(std::hypot(c.points[static_cast<std::size_t>(k)].position.x() - 0.05, c.points[static_cast<std::size_t>(k)].position.y()) <=
            kR + 1e-9);
    }
  }
  SECTION("a capsule lying along a lying cylinder: two points over their overlap") {
    const auto cap = contact::make_collision_shape(geometry::Capsule<double>{0.01, 0.03});
    const Quat along_x = about_y(std::numbers::pi / 2);
    const auto cp = pose(Vector3d::Zero(), along_x);
    const auto kp = pose({0.02, 0, kR + 0.01 - 0.4e-3}, along_x);  // 0.4 mm into the cylinder's top
    REQUIRE(contact::collide(cyl, cp, cap, kp, 0.002, c, scratch));
    REQUIRE(c.count == 2);
    CHECK((c.normal - Vector3d(0, 0, 1)).norm() < 1e-6);
    double lo = 1, hi = -1;
    for (int k = 0; k < 2; ++k) {
      CHECK(c.points[static_cast<std::size_t>(k)].separation == Approx(-0.4e-3).margin(1e-7));
      lo = std::min(lo, c.points[static_cast<std::size_t>(k)].position.x());
      hi = std::max(hi, c.points[static_cast<std::size_t>(k)].position.x());
    }
    CHECK(lo == Approx(0.02 - 0.03).margin(1e-7));  // the capsule's segment ends
    CHECK(hi == Approx(0.02 + 0.03).margin(1e-7));
  }
}

TEST_CASE("GJK/EPA: signed distances of sphere, capsule and cylinder pairs", "[world][contact][gjk]") {
  const auto cyl = cylinder_shape();
  const auto upright = pose(Vector3d::Zero());
  auto sphere = [](double r) { return contact::make_collision_shape(geometry::Sphere<double>{r}); };
  SECTION("sphere beside the cylinder's side: separated and penetrating") {
    const auto s = sphere(0.02);
    auto d = distance(cyl, upright, s, pose({kR + 0.02 + 0.005, 0, 0.01}));
    CHECK_FALSE(d.penetrating);
    CHECK(d.separation == Approx(0.005).margin(1e-9));
    CHECK((d.normal - Vector3d(1, 0, 0)).norm() < 1e-6);
    CHECK((d.point_a - Vector3d(kR, 0, 0.01)).norm() < 1e-6);
    // Off-axis direction: sphere at 40 degrees around the axis, 3 mm into the side.
    const double phi = 40.0 * std::numbers::pi / 180;
    const Vector3d dir(std::cos(phi), std::sin(phi), 0);
    d = distance(cyl, upright, s, pose((kR + 0.02 - 0.003) * dir + Vector3d(0, 0, -0.02)));
    CHECK_FALSE(d.penetrating);  // the sphere's centre (its GJK core) is still outside
    CHECK(d.separation == Approx(-0.003).margin(1e-8));
    CHECK((d.normal - dir).norm() < 1e-5);
  }
  SECTION("sphere on the cap") {
    const auto s = sphere(0.02);
    const auto d = distance(cyl, upright, s, pose({0.01, 0.005, kH + 0.02 - 0.002}));
    CHECK(d.separation == Approx(-0.002).margin(1e-9));
    CHECK((d.normal - Vector3d(0, 0, 1)).norm() < 1e-6);
  }
  SECTION("sphere off the rim: the normal points from the rim circle to the centre") {
    const Vector3d centre(kR + 0.01, 0, kH + 0.01);
    const double to_rim = std::sqrt(2.0) * 0.01;
    auto d = distance(cyl, upright, sphere(0.01), pose(centre));
    CHECK(d.separation == Approx(to_rim - 0.01).margin(1e-9));
    CHECK((d.normal - Vector3d(1, 0, 1).normalized()).norm() < 1e-6);
    d = distance(cyl, upright, sphere(0.02), pose(centre));
    CHECK(d.separation == Approx(to_rim - 0.02).margin(1e-9));
    CHECK((d.normal - Vector3d(1, 0, 1).normalized()).norm() < 1e-6);
  }
  SECTION("a small sphere deep inside the cylinder: the nearest side wins") {
    const auto d = distance(cyl, upright, sphere(0.005), pose({0.02, 0, 0.0}));
    CHECK(d.penetrating);
    CHECK(d.separation == Approx(-(kR - 0.02) - 0.005).margin(1e-8));
    CHECK((d.normal - Vector3d(1, 0, 0)).norm() < 1e-4);  // EPA on a curved face: depth converges faster
  }
  SECTION("crossed cylinders, separated and penetrating") {
    const auto a = pose(Vector3d::Zero(), about_y(std::numbers::pi / 2));  // axis x
    for (const double gap : {0.005, -0.001, -0.004}) {
      const auto b = pose({0.01, -0.02, 2 * kR + gap}, about_x(std::numbers::pi / 2));  // axis y
      const auto d = distance(cyl, a, cyl, b);
      CAPTURE(gap);
      CHECK(d.penetrating == (gap < 0));
      CHECK(d.separation == Approx(gap).margin(1e-8));
      CHECK((d.normal - Vector3d(0, 0, 1)).norm() < 1e-5);
      CHECK(d.point_a.x() == Approx(0.01).margin(1e-5));
      CHECK(d.point_b.y() == Approx(0.0).margin(1e-5));
    }
    // The narrow phase gives one point between the two side lines.
    contact::ContactSet c;
    REQUIRE(contact::collide_convex(cyl, a, cyl, pose({0.01, -0.02, 2 * kR - 0.001}, about_x(std::numbers::pi / 2)), 0.002, c));
    REQUIRE(c.count == 1);
    CHECK(c.points[0].separation == Approx(-0.001).margin(1e-8));
    CHECK((c.points[0].position - Vector3d(0.01, 0, kR - 0.0005)).norm() < 1e-5);
  }
  SECTION("a capsule across a cylinder's side; far pairs stop early") {
    const auto cap = contact::make_collision_shape(geometry::Capsule<double>{0.01, 0.05});
    const auto d = distance(cyl, upright, cap, pose({kR + 0.01 - 0.002, 0, 0.03}, about_x(std::numbers::pi / 2)));
    CHECK(d.separation == Approx(-0.002).margin(1e-9));
    CHECK((d.normal - Vector3d(1, 0, 0)).norm() < 1e-6);
    contact::ConvexDistance far;
    CHECK_FALSE(contact::convex_distance(contact::ConvexSupport{&cyl, upright}, contact::ConvexSupport{&cap, pose({1, 0, 0})}, 0.01, far));
  }
}

namespace {

struct InclineRun {
  double acceleration{0};          ///< of the centre of mass along the slope, m/s^2 (fitted)
  double angular_acceleration{0};  ///< about the axis, rad/s^2 (fitted)
  double bump{0};                  ///< spread (max - min) of the centre's height above the slope
};

/// A cylinder lying across an incline of `angle` (axis horizontal, rolling down along the slope),
/// friction mu on both bodies; least-squares fit of s(t) = s0 + v0 t + a t^2 / 2 over 0.05-0.55 s.
InclineRun roll_down(double angle, double mu) {
  rigid::RigidWorldSettings st;
  st.enable_sleep = false;
  rigid::RigidWorld w(st);
  const Quat tilt = about_y(angle);  // the slope descends towards +x
  const Vector3d down_slope = tilt * Vector3d::UnitX(), normal = tilt * Vector3d::UnitZ();
  rigid::RigidBodyDesc incline;
  incline.shape = geometry::Box<double>{Vector3d(2.0, 0.5, 0.05)};
  incline.orientation = tilt;
  incline.is_static = true;
  incline.friction = mu;
  w.add_body(incline);
  rigid::RigidBodyDesc can;
  can.shape = geometry::Cylinder<double>{kR, kH};
  can.density = 800;
  can.friction = mu;
  can.orientation = tilt * about_x(std::numbers::pi / 2);  // axis along y: rolls along the slope
  const Vector3d start = (0.05 + kR) * normal - 1.0 * down_slope;
  can.position = start;
  const auto id = w.add_body(can);
  const Vector3d axis = w.orientation(id) * Vector3d::UnitZ();
  Eigen::MatrixXd A(0, 3);
  std::vector<double> ts, ss, ws;
  InclineRun out;
  double lowest = INFINITY, highest = -INFINITY;
  for (int i = 1; i <= 2750; ++i) {
    w.step(kDt);
    const double t = i * kDt;
    if (i >= 250) {  // after settling into the soft contact
      const double height = (w.center_of_mass(id) - start).dot(normal);
      lowest = std::min(lowest, height);
      highest = std::max(highest, height);
    }
    if (i >= 250 && i % 10 == 0) {
      ts.push_back(t);
      ss.push_back((w.center_of_mass(id) - start).dot(down_slope));
      ws.push_back(w.angular_velocity(id).dot(axis));
    }
  }
  const auto n = static_cast<Eigen::Index>(ts.size());
  Eigen::MatrixXd M(n, 3), L(n, 2);
  Eigen::VectorXd s(n), wv(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = ts[static_cast<std::size_t>(k)];
    M.row(k) << 1.0, t, 0.5 * t * t;
    L.row(k) << 1.0, t;
    s[k] = ss[static_cast<std::size_t>(k)];
    wv[k] = ws[static_cast<std::size_t>(k)];
  }
  out.bump = highest - lowest;
  out.acceleration = M.colPivHouseholderQr().solve(s)[2];
  out.angular_acceleration = std::abs(L.colPivHouseholderQr().solve(wv)[1]);
  return out;
}

}  // namespace

TEST_CASE("a cylinder lying on an incline rolls at 2/3 g sin t and slips at g (sin t - mu cos t)", "[world][cylinder][rolling]") {
  const double g = 9.81;
  SECTION("15 degrees, mu = 0.6: rolling without slip") {
    const double t = scenes::deg(15);
    const auto run = roll_down(t, 0.6);
    const double expected = 2.0 / 3.0 * g * std::sin(t);
    INFO("acceleration " << run.acceleration << " m/s^2 vs 2/3 g sin t = " << expected << "; alpha " << run.angular_acceleration
                         << " vs a / r = " << expected / kR << "; height spread " << run.bump << " m");
    CHECK(run.acceleration == Approx(expected).epsilon(0.03));
    CHECK(run.angular_acceleration == Approx(expected / kR).epsilon(0.03));  // rolling: alpha = a / r
    CHECK(run.bump < 1e-5);  // no facet bumps (a 16-sided prism: r (1 - cos(pi / 16)) = 0.58 mm)
  }
  SECTION("30 degrees, mu = 0.1 (tan t > 3 mu): slipping, friction at its Coulomb limit") {
    const double t = scenes::deg(30), mu = 0.1;
    const auto run = roll_down(t, mu);
    const double expected = g * (std::sin(t) - mu * std::cos(t));
    const double alpha = 2.0 * mu * g * std::cos(t) / kR;  // torque mu m g cos t r over I = m r^2 / 2
    INFO("acceleration " << run.acceleration << " vs " << expected << "; alpha " << run.angular_acceleration << " vs " << alpha);
    CHECK(run.acceleration == Approx(expected).epsilon(0.03));
    CHECK(run.angular_acceleration == Approx(alpha).epsilon(0.03));
  }
}

TEST_CASE("rolling resistance: a can rolling on the table slows at r_roll g / (1.5 r), a rocking one comes to rest", "[world][cylinder][rolling]") {
  rigid::RigidWorldSettings st;
  st.enable_sleep = false;
  SECTION("lying, rolling at 0.3 m/s: deceleration from the energy balance") {
    // Rolling without slip with a resisting couple r_roll N: d/dt (m v^2 / 2 + I w^2 / 2) = -r_roll m g w,
    // w = v / r, I = m r^2 / 2  =>  a = -r_roll g / (1.5 r). With r_roll = 0 it rolls on at 0.3 m/s.
    for (const double r_roll : {0.0, 1e-3}) {
      rigid::RigidWorld w(st);
      scenes::add_table(w, r_roll);
      const auto can = scenes::add(w, geometry::Cylinder<double>{kR, kH}, {-0.3, 0, kR}, 800, about_x(std::numbers::pi / 2));
      w.set_velocity(can, {0.3, 0, 0}, {0, 0.3 / kR, 0});
      for (int i = 0; i < 250; ++i) w.step(kDt);  // into the soft contact
      const double v0 = w.linear_velocity(can).x(), t0 = w.time();
      for (int i = 0; i < 2500; ++i) w.step(kDt);
      const double a = (w.linear_velocity(can).x() - v0) / (w.time() - t0);
      const double expected = -r_roll * 9.81 / (1.5 * kR);
      INFO("r_roll " << r_roll << " m: a = " << a << " m/s^2, expected " << expected << "; spin " << w.angular_velocity(can).y() * kR
                     << " m/s vs v " << w.linear_velocity(can).x());
      CHECK(a == Approx(expected).margin(2e-3).epsilon(0.03));
      CHECK(w.angular_velocity(can).y() * kR == Approx(w.linear_velocity(can).x()).margin(1e-4));  // still rolling, not sliding
    }
  }
  SECTION("standing, tilted 0.01 rad on its rim and spinning: at rest within 0.5 s with 0.5 mm, later without") {
    double rest_time[2] = {INFINITY, INFINITY};
    for (int k = 0; k < 2; ++k) {
      rigid::RigidWorld w(st);
      scenes::add_table(w, k == 0 ? 0.0 : 5e-4);
      const double r = 0.0175, h = 0.1, tilt = 0.01;  // a candle stick's collision cylinder
      const auto id = scenes::add(w, geometry::Cylinder<double>{r, h}, {0, 0, h * std::cos(tilt) + r * std::sin(tilt)}, 800, about_y(tilt));
      w.set_velocity(id, Vector3d::Zero(), {0, 0, 1.0});
      for (int i = 1; i <= 10000 && !std::isfinite(rest_time[k]); ++i) {
        w.step(kDt);
        if (w.angular_velocity(id).norm() < 0.01 && w.linear_velocity(id).norm() < 1e-3) rest_time[k] = w.time();
      }
    }
    INFO("at rest (|w| < 0.01 rad/s) after " << rest_time[0] << " s without rolling resistance, " << rest_time[1] << " s with 0.5 mm");
    CHECK(rest_time[1] < 0.5);
    CHECK(rest_time[1] < rest_time[0]);
  }
}

TEST_CASE("a standing and a lying cylinder rest on the table for 5 s", "[world][cylinder][rest]") {
  rigid::RigidWorldSettings st;
  st.enable_sleep = false;  // the solver itself, not the sleeping shortcut
  rigid::RigidWorld w(st);
  scenes::add_table(w);
  const auto standing = scenes::add(w, geometry::Cylinder<double>{kR, kH}, {-0.2, 0, kH});
  const auto lying = scenes::add(w, geometry::Cylinder<double>{kR, kH}, {0.2, 0, kR}, 800, about_x(std::numbers::pi / 2));
  // Measured from the placement (touching, at rest): settling into the soft contact counts too.
  const Vector3d ps = w.position(standing), pl = w.position(lying);
  const Quat qs = w.orientation(standing), ql = w.orientation(lying);
  double drift = 0, rise = 0, sink = 0, turn = 0;
  for (int i = 0; i < 25000; ++i) {
    w.step(kDt);
    if (i % 10 != 0) continue;
    for (const auto& [id, p0, q0] : {std::tuple{standing, ps, qs}, std::tuple{lying, pl, ql}}) {
      const Vector3d d = w.position(id) - p0;
      drift = std::max(drift, std::hypot(d.x(), d.y()));
      rise = std::max(rise, d.z());
      sink = std::max(sink, -d.z());
      turn = std::max(turn, w.orientation(id).angularDistance(q0));
    }
  }
  INFO("drift " << drift << " m, rise " << rise << " m, sink " << sink << " m, rotation " << turn << " rad; lying height "
                << w.position(lying).z() << ", standing " << w.position(standing).z());
  CHECK(drift < 1e-5);
  CHECK(rise < 1e-5);
  CHECK(sink < 1e-5);
  CHECK(turn < 1e-4);
  CHECK(w.position(lying).z() == Approx(kR).margin(0.5e-3));
  CHECK(w.position(standing).z() == Approx(kH).margin(0.5e-3));
}

TEST_CASE("rolling, standing and stacked curved bodies step without heap allocation", "[world][cylinder][alloc]") {
  rigid::RigidWorldSettings st;
  st.enable_sleep = false;
  rigid::RigidWorld w(st);
  scenes::add_table(w);
  scenes::add(w, geometry::Cylinder<double>{kR, kH}, {-0.3, 0, kH});
  scenes::add(w, geometry::Cylinder<double>{0.02, 0.02}, {-0.3, 0, 2 * kH + 0.02});  // on the first's cap
  const auto roller = scenes::add(w, geometry::Cylinder<double>{kR, kH}, {0.0, 0, kR}, 800, about_x(std::numbers::pi / 2));
  w.set_velocity(roller, {0.3, 0, 0}, {0, 0.3 / kR, 0});  // rolling along +x
  scenes::add(w, geometry::Sphere<double>{0.02}, {0.2, 0.2, 0.02});
  scenes::add(w, geometry::Capsule<double>{0.015, 0.03}, {-0.1, 0.25, kR * 2 + 0.015}, 800, about_x(std::numbers::pi / 2));
  scenes::add(w, geometry::Cylinder<double>{kR, kH}, {-0.1, 0.25, kR}, 800, about_x(std::numbers::pi / 2));  // capsule on it
  for (int i = 0; i < 2000; ++i) w.step(kDt);
  const long before = manisoft_test::allocation_count.load();
  for (int i = 0; i < 3000; ++i) w.step(kDt);
  const long allocations = manisoft_test::allocation_count.load() - before;
  CHECK(allocations == 0);
  CHECK(w.linear_velocity(roller).x() > 0.25);  // still rolling (no drag from facets)
}

TEST_CASE("a tilted cylinder dropped on the table settles on its cap without gaining energy", "[world][cylinder][energy]") {
  rigid::RigidWorldSettings st;
  st.enable_sleep = false;
  rigid::RigidWorld w(st);
  scenes::add_table(w);
  // Tilted 20 degrees (less than atan(r / h) = 26.6: it falls back onto its cap), 1 cm up.
  const double t = scenes::deg(20);
  const auto id = scenes::add(w, geometry::Cylinder<double>{kR, kH}, {0, 0, kH * std::cos(t) + kR * std::sin(t) + 0.01}, 800,
                              about_y(t));
  const double start = w.mechanical_energy();
  double lowest = start, worst_gain = 0, worst_time = 0;
  for (int i = 0; i < 15000; ++i) {  // 3 s
    w.step(kDt);
    const double e = w.mechanical_energy();
    if (e - lowest > worst_gain) {
      worst_gain = e - lowest;
      worst_time = w.time();
    }
    lowest = std::min(lowest, e);
  }
  // Bound: what the soft contact may store and give back, a spring of at most m g x 1 um.
  const double spring = w.model(id).mass * 9.81 * 1e-6;
  const double tilt = std::acos(std::clamp((w.orientation(id) * Vector3d::UnitZ()).z(), -1.0, 1.0));
  INFO("largest rise above the running minimum " << worst_gain << " J at t = " << worst_time << " s (bound " << spring
                                                 << " J); final height " << w.position(id).z()
                                                 << ", tilt " << tilt << " rad, speed " << w.linear_velocity(id).norm());
  CHECK(worst_gain <= spring);
  CHECK(tilt < 1e-3);                 // back on its cap
  CHECK(w.position(id).z() == Approx(kH).margin(0.5e-3));
  CHECK(w.linear_velocity(id).norm() < 1e-3);
}

TEST_CASE("three cans lying in a pyramid stand (parallel side lines: two-point contacts)", "[world][cylinder][stack]") {
  rigid::RigidWorldSettings st;
  st.enable_sleep = false;
  rigid::RigidWorld w(st);
  scenes::add_table(w);
  const Quat along_y = about_x(std::numbers::pi / 2);
  const auto left = scenes::add(w, geometry::Cylinder<double>{kR, kH}, {-kR, 0, kR}, 800, along_y);
  const auto right = scenes::add(w, geometry::Cylinder<double>{kR, kH}, {kR, 0, kR}, 800, along_y);
  // On top, in the groove: centres 2r apart, so sqrt(3) r above the lower ones.
  const auto top = scenes::add(w, geometry::Cylinder<double>{kR, kH}, {0, 0, kR + std::sqrt(3.0) * kR}, 800, along_y);
  const Vector3d p0 = w.position(top);
  for (int i = 0; i < 15000; ++i) w.step(kDt);  // 3 s
  const double moved = (w.position(top) - p0).norm();
  INFO("top moved " << moved << " m; lower cans at x = " << w.position(left).x() << ", " << w.position(right).x());
  CHECK(moved < 0.5e-3);
  CHECK(w.position(left).x() == Approx(-kR).margin(0.5e-3));
  CHECK(w.position(right).x() == Approx(kR).margin(0.5e-3));
  for (const auto& m : w.manifolds()) {
    if (m.body_a != 0 && m.count > 0) CHECK(m.count == 2);  // can against can: the two ends of the line
  }
}

TEST_CASE("GJK/EPA answers are optimal over the support-function bounds (random poses)", "[world][contact][gjk]") {
  // With M = A - B (cores), h(u) = max over M of u . x = u . (s_A(u) - s_B(-u)):
  //  separated: the distance is max over unit u of -h(-u), reached at u = -n (n from A to B);
  //  overlapping: the penetration depth is min over unit u of h(u), reached at u = n.
  std::mt19937_64 rng(20261124);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  auto vector = [&](double half) {  // one draw per statement: argument order is unspecified
    Vector3d u;
    for (int k = 0; k < 3; ++k) u[k] = uniform(-half, half);
    return u;
  };
  auto unit = [&]() {
    Vector3d u;
    do u = vector(1.0); while (u.squaredNorm() > 1 || u.squaredNorm() < 1e-4);
    return Vector3d(u.normalized());
  };
  auto rotation = [&]() {
    const double w = uniform(-1, 1);
    const Vector3d xyz = vector(1.0);
    return Quat(w, xyz.x(), xyz.y(), xyz.z()).normalized();
  };
  geometry::ConvexMesh<double> mesh;  // an irregular octahedron
  mesh.vertices = {{0.04, 0, 0}, {-0.03, 0, 0}, {0, 0.05, 0}, {0, -0.02, 0}, {0, 0, 0.035}, {0, 0, -0.045}};
  mesh.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  mesh.source = "octahedron";
  const std::array<contact::CollisionShape, 5> others = {
      cylinder_shape(0.02, 0.04), contact::make_collision_shape(geometry::Sphere<double>{0.025}),
      contact::make_collision_shape(geometry::Capsule<double>{0.015, 0.04}), box_shape(Vector3d(0.03, 0.02, 0.05)),
      contact::make_collision_shape(geometry::PrimitiveShape<double>(mesh))};
  const auto cyl = cylinder_shape();
  int separated = 0, overlapping = 0;
  double worst = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const auto& other = others[static_cast<std::size_t>(trial % 5)];
    const contact::ConvexSupport a{&cyl, pose(Vector3d::Zero(), rotation())};
    const Vector3d where = vector(0.09);
    const contact::ConvexSupport b{&other, pose(where, rotation())};
    contact::ConvexDistance d;
    if (!contact::convex_distance(a, b, 1.0, d)) continue;
    const double radii = a.core_radius() + b.core_radius();
    auto h = [&](const Vector3d& u) { return u.dot(a.support(u) - b.support(-u)); };
    const double core = d.separation + radii;  // signed distance of the cores
    CAPTURE(trial, core, d.normal.transpose());
    REQUIRE(std::abs(d.normal.norm() - 1) < 1e-12);
    if (!d.penetrating) {
      ++separated;
      CHECK(-h(d.normal) == Approx(core).margin(1e-8));  // lower bound -h(-u) at u = -n
      for (int k = 0; k < 200; ++k) {
        const Vector3d u = unit();
        worst = std::max(worst, -h(-u) - core);
      }
      CHECK((d.point_b - d.point_a).dot(d.normal) == Approx(d.separation).margin(1e-8));
    } else {
      ++overlapping;
      CHECK(h(d.normal) == Approx(-core).margin(1e-8));  // reached at u = n
      for (int k = 0; k < 200; ++k) {
        const Vector3d u = unit();
        worst = std::max(worst, -core - h(u));  // no direction with a smaller overlap
      }
    }
  }
  INFO(separated << " separated, " << overlapping << " overlapping; worst bound violation " << worst << " m");
  CHECK(separated > 50);
  CHECK(overlapping > 50);
  CHECK(worst < 1e-8);
}

TEST_CASE("the analytic shortcuts agree with GJK/EPA on shallow contacts (random poses)", "[world][contact][gjk]") {
  // Random poses, then B moved along the GJK/EPA normal to a separation in [-1 mm, 2 mm]: the
  // narrow phase (analytic cylinder-box face and side-side paths, or GJK/EPA + clipping) must find
  // the same normal and deepest separation as GJK/EPA itself.
  std::mt19937_64 rng(424242);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  auto rotation = [&]() {
    Eigen::Vector4d q;
    for (int k = 0; k < 4; ++k) q[k] = uniform(-1, 1);
    return Quat(q[0], q[1], q[2], q[3]).normalized();
  };
  const std::array<contact::CollisionShape, 4> others = {
      cylinder_shape(0.02, 0.04), contact::make_collision_shape(geometry::Sphere<double>{0.025}),
      contact::make_collision_shape(geometry::Capsule<double>{0.015, 0.04}), box_shape(Vector3d(0.03, 0.02, 0.05))};
  const auto cyl = cylinder_shape();
  contact::ContactSet c;
  contact::NarrowPhaseScratch scratch;
  int checked = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const auto& other = others[static_cast<std::size_t>(trial % 4)];
    const contact::Pose pa = pose(Vector3d::Zero(), rotation());
    Vector3d where;
    for (int k = 0; k < 3; ++k) where[k] = uniform(-0.1, 0.1);
    contact::Pose pb = pose(where, rotation());
    contact::ConvexDistance d;
    if (!contact::convex_distance({&cyl, pa}, {&other, pb}, 1.0, d)) continue;
    const double target = uniform(-1e-3, 2e-3);
    pb.translation += (target - d.separation) * d.normal;
    REQUIRE(contact::convex_distance({&cyl, pa}, {&other, pb}, 1.0, d));
    CAPTURE(trial, target, d.separation, d.normal.transpose());
    REQUIRE(contact::collide(cyl, pa, other, pb, 0.002, c, scratch));
    double deepest = 1;
    for (int k = 0; k < c.count; ++k) deepest = std::min(deepest, c.points[static_cast<std::size_t>(k)].separation);
    CHECK(deepest == Approx(d.separation).margin(1e-6));
    CHECK(c.normal.dot(d.normal) > 1 - 1e-6);
    ++checked;
  }
  CHECK(checked > 300);
}

}  // namespace test_curved_contact
