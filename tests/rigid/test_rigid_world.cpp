// RigidWorld against analytic expectations at dt = 2e-4 s: resting, sliding (a = mu g), incline
// stick/slide (a = g (sin - mu cos)), stacks of boxes, off-centre cylinders and nested bowls,
// eight mixed objects, energy of a dropped object, restitution, determinism, the capsule query a
// rod will use, external wrenches, non-finite states, and the pair list against brute-force box overlaps.
#include "../../benchmarks/rigid_scenes.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>

namespace test_rigid_world {  // per-file namespace: the group's tests build as one unity translation unit

using namespace manisoft;
using namespace manisoft::geometry;
using namespace manisoft::rigid;
using Catch::Matchers::Contains;
using Eigen::Vector3d;

namespace {

constexpr double kDt = 2e-4;

rigid::RigidWorldSettings awake_settings() {
  rigid::RigidWorldSettings s;
  s.enable_sleep = false;  // measure the solver itself, not the sleeping shortcut
  return s;
}

/// Runs `seconds` and returns the outcome measured every 10 steps.
scenes::Outcome run(rigid::RigidWorld& w, const scenes::Scene& s, double seconds) {
  scenes::Tracker t;
  t.begin(w, s);
  const int steps = static_cast<int>(std::lround(seconds / kDt));
  for (int i = 0; i < steps; ++i) {
    w.step(kDt);
    if (i % 10 == 0) t.sample(w, s);
  }
  t.sample(w, s);
  t.finish(w, s);
  return t.out;
}

double deepest_penetration(const rigid::RigidWorld& w) {
  double pen = 0;
  for (const auto& m : w.manifolds()) {
    for (int k = 0; k < m.count; ++k) pen = std::max(pen, -m.points[static_cast<std::size_t>(k)].separation);
  }
  return pen;
}

}  // namespace

TEST_CASE("a box resting on the table neither sinks nor drifts", "[world][rest]") {
  rigid::RigidWorld w(awake_settings());
  const auto s = scenes::build(w, "S1");
  scenes::Tracker t;
  t.begin(w, s);
  double max_pen = 0;
  for (int i = 0; i < 50000; ++i) {  // 10 s
    w.step(kDt);
    if (i % 10 == 0) {
      t.sample(w, s);
      max_pen = std::max(max_pen, deepest_penetration(w));
    }
  }
  t.finish(w, s);
  INFO("penetration " << max_pen << " m, drift " << t.out.max_xy_drift << " m, sink " << t.out.max_sink << " m, rise "
                       << t.out.max_rise << " m, tilt " << t.out.max_tilt_deg << " deg");
  CHECK(max_pen < 0.5e-3);
  CHECK(t.out.max_sink < 0.5e-3);
  CHECK(t.out.max_rise < 0.1e-3);
  CHECK(t.out.max_tilt_deg < 0.05);
  CHECK(t.out.max_xy_drift < 0.1e-3);
}

TEST_CASE("an excluded contact is left out, and detected again once the exclusion ends", "[world][exclusion]") {
  // A cube resting on the table: with the table's geometry excluded against it, it falls freely
  // (z drops g t^2 / 2); cleared, the contact is found again and stops it, the same as a run that
  // is saved before and restored after (the exclusion is a setting its owner sets again).
  rigid::RigidWorld w(awake_settings());
  const auto s = scenes::build(w, "S1");
  const BodyId cube = s.bodies[0];
  const BodyId table = 0;
  REQUIRE(w.model(table).is_static);
  for (int i = 0; i < 100; ++i) w.step(kDt);
  const double z0 = w.center_of_mass(cube).z();
  const rigid::RigidWorld::ExcludedContact e{w.model(table).first_geom, w.model(table).geom_count, cube};
  w.set_excluded_contact(e);
  const int n = 50;  // 10 ms: 0.49 mm of free fall
  for (int i = 0; i < n; ++i) w.step(kDt);
  const double t = n * kDt;
  CHECK(z0 - w.center_of_mass(cube).z() == Approx(0.5 * 9.81 * t * t).epsilon(0.05));
  for (const auto& m : w.manifolds()) CHECK(m.count == 0);
  w.set_excluded_contact(std::nullopt);
  rigid::RigidWorld::Snapshot snap;
  w.save(snap);
  for (int i = 0; i < 2000; ++i) w.step(kDt);
  const Vector3d rested = w.center_of_mass(cube);
  CHECK(rested.z() == Approx(z0).margin(0.5e-3));  // pushed back out of the table, at rest on it
  CHECK(w.linear_velocity(cube).norm() < 1e-3);
  w.set_excluded_contact(e);
  w.restore(snap);
  w.set_excluded_contact(std::nullopt);
  for (int i = 0; i < 2000; ++i) w.step(kDt);
  CHECK(std::memcmp(w.center_of_mass(cube).data(), rested.data(), sizeof(rested)) == 0);
  // Geometries of two bodies, or of the other body itself, are refused with the range named.
  REQUIRE(w.geoms().size() == 2);  // the table's and the cube's
  CHECK_THROWS_WITH(w.set_excluded_contact(rigid::RigidWorld::ExcludedContact{0, 2, cube}), Contains("excluded contact: geometries [0, 2)"));
  CHECK_THROWS_WITH(w.set_excluded_contact(rigid::RigidWorld::ExcludedContact{w.model(cube).first_geom, 1, cube}), Contains("other than body"));
}

TEST_CASE("a sliding box decelerates at mu g", "[world][friction]") {
  rigid::RigidWorld w(awake_settings());
  const auto s = scenes::build(w, "S6");  // 1 m/s, mu = 0.5
  const rigid::BodyId id = s.bodies[0];
  double v1 = 0, v2 = 0;
  for (int i = 1; i <= 900; ++i) {
    w.step(kDt);
    if (i == 100) v1 = w.linear_velocity(id).x();
    if (i == 900) v2 = w.linear_velocity(id).x();
  }
  const double decel = (v1 - v2) / (800 * kDt);
  INFO("deceleration " << decel << " m/s^2, mu g = 4.905");
  CHECK(decel == Approx(0.5 * 9.81).epsilon(0.03));
  for (int i = 0; i < 2000; ++i) w.step(kDt);  // it stops and stays
  CHECK(w.linear_velocity(id).norm() < 1e-6);
  const double stop = w.position(id).x() - (-0.3);
  CHECK(stop == Approx(1.0 / (2 * 0.5 * 9.81)).epsilon(0.03));  // v0^2 / (2 mu g)
}

TEST_CASE("a box on an incline sticks below the friction angle and slides above it", "[world][friction]") {
  SECTION("20 degrees, mu = 0.5: true static friction") {
    rigid::RigidWorld w(awake_settings());
    const auto s = scenes::build(w, "S5a");
    const Vector3d p0 = w.position(s.bodies[0]);
    for (int i = 0; i < 25000; ++i) w.step(kDt);  // 5 s
    const double creep = (w.position(s.bodies[0]) - p0).norm();
    INFO("creep over 5 s: " << creep << " m (MuJoCo: 9.0e-3 / 4.5e-4)");
    CHECK(creep < 0.1e-3);
  }
  SECTION("30 degrees: a = g (sin - mu cos), no chattering") {
    rigid::RigidWorld w(awake_settings());
    const auto s = scenes::build(w, "S5b");
    const rigid::BodyId id = s.bodies[0];
    double v1 = 0, v2 = 0;
    int airborne = 0;
    for (int i = 1; i <= 10000; ++i) {
      w.step(kDt);
      if (i == 2500) v1 = w.linear_velocity(id).norm();
      if (i == 10000) v2 = w.linear_velocity(id).norm();
      if (i > 250 && w.touching_point_count() == 0) ++airborne;
    }
    const double a = (v2 - v1) / (7500 * kDt);
    const double expected = 9.81 * (std::sin(scenes::deg(30)) - 0.5 * std::cos(scenes::deg(30)));
    INFO("acceleration " << a << " vs " << expected << "; steps without contact: " << airborne);
    CHECK(a == Approx(expected).epsilon(0.03));
    CHECK(airborne == 0);
  }
}

TEST_CASE("a stack of five boxes stands", "[world][stack][slow]") {
  rigid::RigidWorld w(awake_settings());
  const auto s = scenes::build(w, "S2");
  const auto out = run(w, s, 10.0);
  INFO("drift " << out.max_xy_drift << " sink " << out.max_sink << " rise " << out.max_rise << " tilt " << out.max_tilt_deg);
  CHECK(out.max_xy_drift < 2e-3);
  CHECK(out.max_sink < 0.5e-3);
  CHECK(out.max_rise < 0.5e-3);      // no body pops up out of its contact
  CHECK(out.max_tilt_deg < 0.5);     // and none tips over
  CHECK(out.ejected == 0);
}

TEST_CASE("three cylinders stacked 5 mm off-centre stand", "[world][stack][slow]") {
  rigid::RigidWorld w(awake_settings());
  scenes::add_table(w);
  scenes::Scene s;
  for (int k = 0; k < 3; ++k) {
    s.bodies.push_back(scenes::add(w, geometry::Cylinder<double>{0.03, 0.02}, {0.005 * k, 0, 0.02 + 0.04 * k}));
    s.names.push_back("cyl" + std::to_string(k));
  }
  const auto out = run(w, s, 10.0);
  INFO("drift " << out.max_xy_drift << " sink " << out.max_sink << " rise " << out.max_rise << " tilt " << out.max_tilt_deg);
  CHECK(out.max_xy_drift < 2e-3);
  CHECK(out.max_sink < 0.5e-3);
  CHECK(out.max_rise < 0.5e-3);      // no body pops up out of its contact
  CHECK(out.max_tilt_deg < 0.5);     // and none tips over
  CHECK(out.ejected == 0);
}

TEST_CASE("four nested bowls rest in each other", "[world][stack][compound][slow]") {
  rigid::RigidWorld w(awake_settings());
  scenes::add_table(w);
  const geometry::VesselParams bowl{0.05, 0.05, 0.004, scenes::deg(40), 12};
  scenes::Scene s;
  for (int k = 0; k < 4; ++k) {
    s.bodies.push_back(scenes::add(w, geometry::make_vessel(bowl), {0, 0, k * geometry::nesting_offset(bowl)}));
    s.names.push_back("bowl" + std::to_string(k));
  }
  const auto out = run(w, s, 10.0);
  INFO("drift " << out.max_xy_drift << " sink " << out.max_sink << " rise " << out.max_rise << " tilt " << out.max_tilt_deg);
  CHECK(out.max_xy_drift < 2e-3);
  CHECK(out.max_sink < 0.5e-3);
  CHECK(out.max_rise < 0.5e-3);      // no body pops up out of its contact
  CHECK(out.max_tilt_deg < 0.5);     // and none tips over
  CHECK(out.ejected == 0);
}

TEST_CASE("eight mixed objects rest apart on the table", "[world][rest][slow]") {
  rigid::RigidWorld w(awake_settings());
  const auto s = scenes::build(w, "S4");
  scenes::Tracker t;
  t.begin(w, s);
  const auto out = run(w, s, 10.0);
  double moved = 0;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) moved = std::max(moved, (w.position(s.bodies[i]) - t.start[i]).norm());
  INFO("largest displacement " << moved << " (" << out.worst << "), ejected " << out.ejected);
  CHECK(moved < 0.1e-3);
  CHECK(out.ejected == 0);
}

TEST_CASE("a dropped object never gains energy", "[world][energy]") {
  for (const bool sphere : {false, true}) {
    rigid::RigidWorld w(awake_settings());
    scenes::add_table(w);
    rigid::RigidBodyDesc d;
    d.shape = sphere ? geometry::Shape<double>(geometry::Sphere<double>{0.03}) : geometry::Shape<double>(geometry::Box<double>{Vector3d(0.03, 0.02, 0.025)});
    d.density = 800;
    d.position = {0, 0, 0.15};
    d.orientation = scenes::euler_xyz(20, 35, 10);
    d.angular_velocity = {1, -2, 0.5};
    const rigid::BodyId id = w.add_body(d);
    // Kinetic + potential energy may only rise above its lowest value so far by what the soft
    // contact stores in its penetration (a spring of at most m g x 1 um here): 1e-6 of the start.
    double previous = w.mechanical_energy();
    const double start = previous;
    double lowest = start, worst_gain = 0;
    for (int i = 0; i < 10000; ++i) {
      w.step(kDt);
      previous = w.mechanical_energy();
      worst_gain = std::max(worst_gain, previous - lowest);
      lowest = std::min(lowest, previous);
    }
    INFO((sphere ? "sphere" : "box") << ": largest rise above the running minimum " << worst_gain << " J; start "
                                      << start << " end " << previous);
    CHECK(worst_gain <= 1e-6 * start);
    CHECK(previous < start);
    CHECK(w.position(id).z() > 0);
  }
}

TEST_CASE("restitution is respected", "[world][restitution]") {
  for (const double e : {0.0, 0.5, 0.8}) {
    rigid::RigidWorld w(awake_settings());
    scenes::add_table(w);
    rigid::RigidBodyDesc d;
    d.shape = geometry::Sphere<double>{0.02};
    d.density = 800;
    d.restitution = e;
    const double drop = 0.2;
    d.position = {0, 0, 0.02 + drop};
    const rigid::BodyId id = w.add_body(d);
    bool bounced = false;
    double peak = 0;
    for (int i = 0; i < 7000; ++i) {
      w.step(kDt);
      const double vz = w.linear_velocity(id).z();
      if (!bounced && vz > 0 && w.position(id).z() < 0.03) bounced = true;
      if (bounced) peak = std::max(peak, w.position(id).z() - 0.02);
    }
    INFO("e = " << e << ": rebound height " << peak << " vs e^2 h = " << e * e * drop);
    CHECK(peak == Approx(e * e * drop).margin(0.03 * drop));
  }
}

TEST_CASE("stepping is deterministic: two runs are bit-identical", "[world][determinism]") {
  auto simulate = [] {
    rigid::RigidWorld w;  // sleeping enabled: the island logic must be deterministic too
    const auto s = scenes::build(w, "S4");
    rigid::RigidBodyDesc d;
    d.shape = geometry::Capsule<double>{0.02, 0.05};
    d.density = 700;
    d.position = {-0.2, -0.2, 0.3};
    d.orientation = scenes::euler_xyz(30, 20, 0);
    w.add_body(d);
    for (int i = 0; i < 3000; ++i) w.step(kDt);
    std::vector<double> out;
    for (rigid::BodyId id = 0; id < w.body_count(); ++id) {
      const auto& st = w.state(id);
      for (int k = 0; k < 3; ++k) out.push_back(st.position[k]);
      for (int k = 0; k < 4; ++k) out.push_back(st.orientation.coeffs()[k]);
      for (int k = 0; k < 3; ++k) out.push_back(st.linear_velocity[k]);
    }
    return out;
  };
  const auto a = simulate();
  const auto b = simulate();
  REQUIRE(a.size() == b.size());
  CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

TEST_CASE("capsule query: contacts a rod element would use", "[world][query]") {
  rigid::RigidWorld w(awake_settings());
  scenes::add_table(w);
  const rigid::BodyId box = scenes::add(w, scenes::box(0.05, 0.05, 0.05), {0.3, 0, 0.05});
  const rigid::BodyId ball = scenes::add(w, geometry::Sphere<double>{0.04}, {-0.3, 0, 0.04});
  std::vector<CapsuleContact> contacts;
  SECTION("lying on the box top: two points, normal into the box") {
    w.query_capsule({0.27, 0, 0.118}, {0.33, 0, 0.118}, 0.02, 0.005, contacts);
    REQUIRE(contacts.size() == 2);
    for (const auto& c : contacts) {
      CHECK(c.body == box);
      CHECK(c.separation == Approx(-0.002).margin(1e-12));
      CHECK((c.normal - Vector3d(0, 0, -1)).norm() < 1e-12);
    }
    CHECK(contacts[0].segment_parameter == Approx(0.0).margin(1e-12));
    CHECK(contacts[1].segment_parameter == Approx(1.0).margin(1e-12));
  }
  SECTION("near the box edge: the normal is the true one (FCL's GST_LIBCCD gets it wrong)") {
    // Segment parallel to the box's top +x edge, 3 cm out and 3 cm up: normal along (-1, 0, -1)/sqrt 2.
    w.query_capsule({0.38, -0.02, 0.13}, {0.38, 0.02, 0.13}, 0.045, 0.0, contacts);
    REQUIRE(contacts.size() >= 1);
    const double dist = std::sqrt(2.0) * 0.03;
    CHECK(contacts[0].separation == Approx(dist - 0.045).margin(1e-12));
    CHECK((contacts[0].normal - Vector3d(-1, 0, -1).normalized()).norm() < 1e-9);
  }
  SECTION("against a sphere and the table, nothing out of range") {
    w.query_capsule({-0.3, -0.05, 0.1}, {-0.3, 0.05, 0.1}, 0.01, 0.02, contacts);
    REQUIRE(contacts.size() == 1);
    CHECK(contacts[0].body == ball);
    CHECK(contacts[0].separation == Approx(0.1 - 0.04 - 0.04 - 0.01).margin(1e-12));
    w.query_capsule({0, 0.2, 0.5}, {0.1, 0.2, 0.5}, 0.01, 0.01, contacts);
    CHECK(contacts.empty());
  }
}

TEST_CASE("external wrenches: force at a point gives the Newton-Euler response", "[world][wrench]") {
  rigid::RigidWorldSettings st = awake_settings();
  st.gravity.setZero();
  rigid::RigidWorld w(st);
  rigid::RigidBodyDesc d;
  d.shape = geometry::Box<double>{Vector3d(0.1, 0.05, 0.02)};
  d.mass = 2.0;
  const rigid::BodyId id = w.add_body(d);
  const Vector3d f(0, 3, 0), p(0.1, 0, 0);  // at the +x face centre
  w.add_force_at_point(id, f, p);
  w.step(kDt);
  CHECK((w.linear_velocity(id) - f / 2.0 * kDt).norm() < 1e-15);
  const double izz = 2.0 / 3.0 * (0.01 + 0.0025);
  CHECK(w.angular_velocity(id).z() == Approx(0.1 * 3.0 / izz * kDt).epsilon(1e-9));
  w.step(kDt);  // forces last one step
  CHECK((w.linear_velocity(id) - f / 2.0 * kDt).norm() < 1e-15);
}

TEST_CASE("a non-finite state is reported with the body and the world keeps its last state", "[world][input]") {
  rigid::RigidWorldSettings st = awake_settings();
  st.gravity.setZero();
  rigid::RigidWorld w(st);
  rigid::RigidBodyDesc d;
  d.shape = geometry::Sphere<double>{0.01};
  d.density = 1000;
  d.name = "pebble";
  const rigid::BodyId id = w.add_body(d);
  w.step(kDt);
  const Vector3d before = w.position(id);
  w.add_force(id, Vector3d(1e308, 0, 0));
  w.add_force(id, Vector3d(1e308, 0, 0));  // sum overflows to inf inside the step
  CHECK_THROWS_WITH(w.step(kDt), Contains("rigid body 0") && Contains("pebble") && Contains("non-finite"));
  CHECK(w.position(id) == before);
}

TEST_CASE("resting bodies fall asleep and wake when pushed", "[world][sleep]") {
  rigid::RigidWorld w;  // sleeping on
  const auto s = scenes::build(w, "S2");
  for (int i = 0; i < 10000; ++i) w.step(kDt);  // 2 s
  for (auto id : s.bodies) CHECK_FALSE(w.is_awake(id));
  w.add_force(s.bodies[4], Vector3d(0.5, 0, 0));
  w.step(kDt);
  for (auto id : s.bodies) CHECK(w.is_awake(id));  // the whole island wakes
  CHECK(w.linear_velocity(s.bodies[4]).x() > 0);
}

TEST_CASE("the manifold list holds exactly the pairs whose fat boxes overlap, also across undone steps", "[world][broadphase][rollback]") {
  // Two bowls (compounds) nesting, a box sliding into them, a ball thrown over them: pairs appear and
  // separate all the time. The expectation is the brute-force overlap test of every two geoms'
  // fat boxes (closed intervals, as FCL's AABB::overlap), for geoms of two bodies not both static.
  const geometry::VesselParams bowl{0.05, 0.05, 0.004, scenes::deg(40), 12};
  auto make = [&] {
    rigid::RigidWorld w;
    scenes::add_table(w);
    scenes::add(w, geometry::make_vessel(bowl), {0, 0, 0});
    const auto b = scenes::add(w, geometry::make_vessel(bowl), {0.01, 0, 0.12});
    const auto box = scenes::add(w, scenes::box(0.02, 0.02, 0.02), {0.3, 0.01, 0.02});
    const auto ball = scenes::add(w, geometry::Sphere<double>{0.015}, {-0.3, 0.05, 0.2});
    w.set_velocity(b, {0.05, 0, -0.3}, {0, 0, 2});
    w.set_velocity(box, {-0.9, 0, 0}, {0, 0, 0});
    w.set_velocity(ball, {0.8, -0.1, 0.6}, {0, 3, 0});
    return std::make_pair(std::move(w), ball);
  };
  auto expected_keys = [](const rigid::RigidWorld& w) {
    std::vector<std::uint64_t> keys;
    const auto& g = w.geoms();
    for (std::uint32_t a = 0; a < g.size(); ++a) {
      for (std::uint32_t b = a + 1; b < g.size(); ++b) {
        if (g[a].body == g[b].body || (w.model(g[a].body).is_static && w.model(g[b].body).is_static)) continue;
        if (((g[a].fat_lo.array() <= g[b].fat_hi.array()) && (g[b].fat_lo.array() <= g[a].fat_hi.array())).all())
          keys.push_back((std::uint64_t(a) << 32) | b);
      }
    }
    return keys;
  };
  auto keys_of = [](const rigid::RigidWorld& w) {
    std::vector<std::uint64_t> keys;
    for (const auto& m : w.manifolds()) keys.push_back(m.key());
    return keys;
  };
  // Everything a manifold carries between steps, slot by slot.
  auto same_memories = [](const rigid::RigidWorld::Snapshot& a, const rigid::RigidWorld::Snapshot& b) {
    if (a.manifolds.size() != b.manifolds.size()) return false;
    for (std::size_t i = 0; i < a.manifolds.size(); ++i) {
      const auto &x = a.manifolds[i], &y = b.manifolds[i];
      bool same = x.geom_a == y.geom_a && x.geom_b == y.geom_b && x.count == y.count && x.owner == y.owner &&
                  x.fresh == y.fresh && x.rolling == y.rolling && x.normal_local == y.normal_local &&
                  x.travel_a == y.travel_a && x.travel_b == y.travel_b && x.tangent_impulse == y.tangent_impulse &&
                  x.drift == y.drift && x.twist_impulse == y.twist_impulse && x.twist_drift == y.twist_drift;
      for (std::size_t k = 0; k < x.points.size(); ++k) {
        same = same && x.points[k].anchor_a == y.points[k].anchor_a && x.points[k].anchor_b == y.points[k].anchor_b &&
               x.points[k].base_separation == y.points[k].base_separation && x.points[k].normal_impulse == y.points[k].normal_impulse;
      }
      if (!same) return false;
    }
    return true;
  };
  auto [world, ball] = make();
  auto twin = make().first;  // never fails
  rigid::RigidWorld::Snapshot before_failure, after_undo;
  int changes = 0, undone_changes = 0;
  for (int i = 0; i < 4000; ++i) {
    const auto before = keys_of(twin);
    twin.step(kDt);
    auto after = keys_of(twin);
    const bool changed = after != before;
    changes += changed;
    // When the twin's step changed the list, the same step of `world` fails at its end (two
    // finite forces on the ball sum to infinity) and is undone; then it is taken again.
    if (changed && world.state(ball).sleep_time == 0.0) {
      world.save(before_failure);
      world.add_force(ball, Vector3d(1e308, 0, 0));
      world.add_force(ball, Vector3d(1e308, 0, 0));
      REQUIRE_THROWS_AS(world.step(kDt), Diverged);
      REQUIRE(keys_of(world) == before);  // the list as it was, slot for slot
      world.save(after_undo);
      REQUIRE(same_memories(before_failure, after_undo));  // with every manifold's memory
      ++undone_changes;
    }
    world.step(kDt);
    REQUIRE(keys_of(world) == after);  // same slots in the same order as the twin's
    std::sort(after.begin(), after.end());
    REQUIRE(std::adjacent_find(after.begin(), after.end()) == after.end());  // no pair twice
    REQUIRE(after == expected_keys(twin));
    for (rigid::BodyId id = 0; id < world.body_count(); ++id) {
      REQUIRE(world.state(id).position == twin.state(id).position);
      REQUIRE(world.state(id).orientation.coeffs() == twin.state(id).orientation.coeffs());
    }
  }
  INFO("list changes " << changes << ", undone " << undone_changes);
  CHECK(changes >= 20);
  CHECK(undone_changes >= 10);
}

}  // namespace test_rigid_world
