// Each grasp annotation and each receptacle of the generated asset catalogue (paper section 3.3,
// assets) checked in the physics:
//  - every graspable object's every grasp: the object rests on the tabletop world's table, the
//    parallel gripper (interaction::ParallelGripper, held kinematically) is put at the annotated
//    grasp pose without touching it, closes, reports the grasp (its weld) with a finger width
//    within its limits, and lifts the object; independently, the object's visual mesh over the
//    fingers' height range lies between the open fingers and its extent along the closing axis
//    is the annotated width;
//  - the approach, grasp and lift poses of every grasp, for the object at two reachable table
//    spots (x 0.50 and 0.60 m, y 0: in the middle of the band the tool-down arm reaches,
//    DESIGN.md section 10), are equilibria of the arm within its actuation limits (the inverse
//    statics, as world_demo and the reach environment use it; lift with the heaviest graspable
//    payload). Closer to the mount (x 0.45) the high approach and lift poses need up to 1.2 times
//    the bend limit: the arm's reach, not the annotations;
//  - every container or tableware asset holds a small cube dropped into its receptacle: after
//    settling the cube is inside the inner volume and at rest.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "manisoft/assets/catalog.hpp"
#include "manisoft/interaction/gripper.hpp"
#include "manisoft/rod/inverse_statics.hpp"
#include "manisoft/world/tabletop_scene.hpp"

namespace test_asset_grasps {  // per-file namespace: the group's tests build as one unity translation unit

namespace {

using Eigen::Vector3d;
using manisoft::assets::Asset;
using manisoft::math::Pose;
using manisoft::rigid::BodyId;
namespace rigid = manisoft::rigid;
namespace world = manisoft::world;
namespace interaction = manisoft::interaction;
constexpr double kDt = 2e-4;

/// The tabletop world's table (world::tabletop_table(): top at z = 0.75) as a static body.
double add_table(rigid::RigidWorld& w) {
  const world::TableDesc t = world::tabletop_table();
  rigid::RigidBodyDesc d;
  d.shape = manisoft::geometry::Box<double>{Vector3d(t.half_x, t.half_y, 0.5 * t.thickness)};
  d.position = t.top_center - Vector3d(0, 0, 0.5 * t.thickness);
  d.is_static = true;
  d.friction = t.friction;
  d.name = "table";
  w.add_body(d);
  return t.top_center.z();
}

BodyId add_asset(rigid::RigidWorld& w, const Asset& a, const Pose<double>& at) {
  rigid::RigidBodyDesc d;
  d.shape = a.collision;
  d.mass = a.mass;
  d.inertia = a.inertia;
  d.friction = a.friction;
  d.position = at.translation;
  d.orientation = Eigen::Quaterniond(at.rotation);
  d.name = a.id;
  return w.add_body(d);
}

/// Extent along the gripper's closing axis (x) of a body's collision geometry that reaches into
/// the fingers' span (gripper frame z in [z0, z1]), from the geometries' bounding boxes in the
/// gripper frame: exact for the catalogue's upright cylinders and aligned boxes.
double collision_width(const rigid::RigidWorld& w, BodyId b, BodyId gripper, double z0, double z1) {
  const Eigen::Matrix3d rg = w.orientation(gripper).toRotationMatrix();
  const Vector3d xg = w.position(gripper);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  const auto& m = w.model(b);
  for (std::uint32_t g = m.first_geom; g < m.first_geom + m.geom_count; ++g) {
    const auto gp = w.geom_pose(g);
    manisoft::contact::Pose local;
    local.rotation = rg.transpose() * gp.rotation;
    local.translation = rg.transpose() * (gp.translation - xg);
    Vector3d glo, ghi;
    w.geoms()[g].shape.bounds(local, glo, ghi);
    if (ghi.z() <= z0 || glo.z() >= z1) continue;
    lo = std::min(lo, glo.x());
    hi = std::max(hi, ghi.x());
  }
  return hi - lo;
}

Pose<double> compose(const Pose<double>& a, const Pose<double>& b) {
  return Pose<double>{a.rotation * b.rotation, a.translation + a.rotation * b.translation};
}

/// Extent along x of a mesh (points given in some frame) inside the slab z in [z0, z1]: the
/// extremes of a linear function over a polyhedral surface cut by two planes lie at its vertices
/// inside the slab or where its edges cross the planes.
struct SlabExtent {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  bool empty() const { return !(hi >= lo); }
};
SlabExtent slab_extent_x(const manisoft::render::Mesh& m, const Pose<double>& frame_in_mesh, double z0, double z1) {
  std::vector<Vector3d> p(m.positions.size());
  for (std::size_t i = 0; i < p.size(); ++i)
    p[i] = frame_in_mesh.rotation.transpose() * (m.positions[i].cast<double>() - frame_in_mesh.translation);
  SlabExtent e;
  auto take = [&e](double x) {
    e.lo = std::min(e.lo, x);
    e.hi = std::max(e.hi, x);
  };
  for (const auto& q : p)
    if (q.z() >= z0 && q.z() <= z1) take(q.x());
  for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    for (int k = 0; k < 3; ++k) {
      const Vector3d& a = p[m.indices[t + std::size_t(k)]];
      const Vector3d& b = p[m.indices[t + std::size_t((k + 1) % 3)]];
      for (double z : {z0, z1}) {
        if ((a.z() - z) * (b.z() - z) < 0) take(a.x() + (z - a.z()) / (b.z() - a.z()) * (b.x() - a.x()));
      }
    }
  }
  return e;
}

/// The gripper body kept still (velocity set each step, its weight cancelled), as in
/// tests/world/test_gripper.cpp.
void step_kinematic(rigid::RigidWorld& w, interaction::ParallelGripper& g, const Vector3d& v) {
  w.set_velocity(g.body(), v, Vector3d::Zero());
  w.add_force(g.body(), -w.model(g.body()).mass * w.settings().gravity);
  g.pre_step(w, kDt);
  w.step(kDt);
}

Pose<double> at(double x, double y, double z) { return Pose<double>{Eigen::Matrix3d::Identity(), Vector3d(x, y, z)}; }

}  // namespace

TEST_CASE("every grasp annotation closes the gripper on its object on the table", "[assets][grasp]") {
  const interaction::ParallelGripperParameters gp;
  const manisoft::assets::GraspGripper gg;
  int checked = 0;
  for (const Asset& a : manisoft::assets::object_catalog()) {
    for (std::size_t k = 0; k < a.grasps.size(); ++k) {
      const auto& grasp = a.grasps[k];
      INFO(a.id << " grasp " << k);
      // Independent of the physics: the visual mesh between the fingers (gripper frame z from the
      // palm to the fingertips) lies inside the open fingers, and its width is the annotation's.
      const double tip_z = gp.palm_thickness + gp.finger_length;
      SlabExtent e;
      for (const auto& part : a.visual) {
        const SlabExtent pe = slab_extent_x(part.mesh, grasp.grasp, gp.palm_thickness, tip_z);
        e.lo = std::min(e.lo, pe.lo);
        e.hi = std::max(e.hi, pe.hi);
      }
      REQUIRE(!e.empty());  // the fingers reach the object
      CHECK(e.hi - e.lo < gp.open_width);
      CHECK(e.lo > -0.5 * gp.open_width);
      CHECK(e.hi < 0.5 * gp.open_width);
      CHECK(grasp.width == Approx(e.hi - e.lo).margin(2e-5));
      // No part of the object above the palm's face, and the fingertips clear of the table.
      const double top = a.bounding_center.z() + a.bounding_half_extents.z();
      const Vector3d palm_face = grasp.grasp.translation + grasp.grasp.rotation.col(2) * gp.palm_thickness;
      const Vector3d tips = grasp.grasp.translation + grasp.grasp.rotation.col(2) * tip_z;
      CHECK(palm_face.z() > top);
      CHECK(tips.z() >= gg.table_clearance - 1e-12);

      rigid::RigidWorld w;
      const double table_top = add_table(w);
      const Pose<double> place = at(0.5, 0.0, table_top);
      const BodyId object = add_asset(w, a, place);
      const Pose<double> gpose = compose(place, grasp.grasp);
      auto ee = interaction::make_parallel_gripper(gp);
      ee.body.position = gpose.translation;
      ee.body.orientation = Eigen::Quaterniond(gpose.rotation);
      interaction::ParallelGripper gripper(gp);
      gripper.attach(w.add_body(ee.body));
      const Vector3d x0 = w.position(object);
      for (int i = 0; i < 50; ++i) step_kinematic(w, gripper, Vector3d::Zero());
      // The open gripper at the grasp pose does not disturb the object.
      CHECK((w.position(object) - x0).norm() < 1e-3);
      CHECK(gripper.finger_width() == Approx(gp.open_width));
      gripper.command(1);
      // The fingers close at open_width / stroke_time: they reach the object's collision
      // geometry (a lathe's is its equal-volume cylinder, narrower than the visual where the
      // profile bulges) in (open_width - width) / that speed, and stop there on the object.
      const double width = collision_width(w, object, gripper.body(), gp.palm_thickness, tip_z);
      const int stroke_steps = int(std::ceil((gp.open_width - width) / gp.open_width * gp.stroke_time / kDt));
      int steps = 0;
      do {
        step_kinematic(w, gripper, Vector3d::Zero());
      } while (gripper.closing() && ++steps < 2 * stroke_steps + 10);
      REQUIRE(gripper.held());
      CHECK(*gripper.held() == object);
      CHECK(gripper.state() == 1);
      CHECK(steps <= stroke_steps + 2);
      CHECK(gripper.finger_width() == Approx(width).margin(1.2e-3));
      // The object was not pushed out of place on the way.
      CHECK((w.position(object) - x0).norm() < 3e-3);
      // Lift 3.5 cm (speed ramped to 0.3 m/s over 0.05 s): the weld carries the object.
      for (int i = 0; i < 700; ++i) step_kinematic(w, gripper, Vector3d(0, 0, 0.3 * std::min(1.0, i / 250.0)));
      REQUIRE(gripper.held());
      CHECK(!gripper.slipped());
      CHECK(w.position(object).z() - x0.z() > 0.03);
      ++checked;
    }
  }
  CHECK(checked >= 109);
}

TEST_CASE("every grasp's approach, grasp and lift poses are within the arm's actuation limits", "[assets][grasp][reach]") {
  const interaction::ParallelGripperParameters gp;
  const world::ArmWorldSettings settings;
  const auto arm = world::tabletop_arm_parameters();
  manisoft::rod::InverseStatics<double> empty(manisoft::rod::make_arm_model(arm, gp.mass), {}, settings.limits);
  double heaviest = 0;
  const auto objects = manisoft::assets::object_catalog();
  for (const Asset& a : objects) heaviest = std::max(heaviest, a.mass);
  manisoft::rod::InverseStatics<double> loaded(manisoft::rod::make_arm_model(arm, gp.mass + heaviest), {}, settings.limits);
  const double table_top = world::tabletop_table().top_center.z();
  int solved = 0;
  for (double x : {0.50, 0.60}) {
    const Pose<double> place = at(x, 0.0, table_top);
    for (const Asset& a : objects) {
      for (std::size_t k = 0; k < a.grasps.size(); ++k) {
        const auto& g = a.grasps[k];
        for (int which = 0; which < 3; ++which) {
          INFO(a.id << " grasp " << k << " at x = " << x << (which == 0 ? " approach" : which == 1 ? " grasp" : " lift"));
          auto& statics = which == 2 ? loaded : empty;
          const Pose<double> target = compose(place, which == 0 ? g.approach : which == 1 ? g.grasp : g.lift);
          const auto r = statics.solve_cold(target);
          CHECK(r.converged);
          CHECK(r.position_error < 1e-6);
          CHECK(r.within_limits);
          // Independently of the solver's flag: every actuated element torque within its limit.
          const auto& tau = statics.feedforward();
          for (int e = 0; e < tau.rows(); ++e)
            for (int c = 0; c < 3; ++c) CHECK(std::abs(tau(e, c)) <= settings.limits.limit(c) * (1 + 1e-12));
          ++solved;
        }
      }
    }
  }
  CHECK(solved >= 2 * 3 * 109);
}

TEST_CASE("every container holds a small cube dropped into it", "[assets][receptacle]") {
  int containers = 0;
  for (const Asset& a : manisoft::assets::object_catalog()) {
    for (std::size_t k = 0; k < a.receptacles.size(); ++k) {
      const auto& rc = a.receptacles[k];
      INFO(a.id << " receptacle " << k);
      ++containers;
      rigid::RigidWorld w;
      const double table_top = add_table(w);
      const Pose<double> place = at(0.5, 0.0, table_top);
      const BodyId container = add_asset(w, a, place);
      // A cube (edge 2.5 cm, 20 g) 3 cm above the opening, centred over the placement point and
      // turned 20 degrees about z.
      const double half = 0.0125;
      const Pose<double> placement = compose(place, rc.placement);
      const Pose<double> opening = compose(place, rc.opening);
      rigid::RigidBodyDesc cube;
      cube.shape = manisoft::geometry::Box<double>{Vector3d::Constant(half)};
      cube.mass = 0.02;
      cube.friction = 0.5;
      cube.position = Vector3d(placement.translation.x(), placement.translation.y(), opening.translation.z() + 0.03 + half);
      cube.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(20.0 * std::numbers::pi / 180.0, Vector3d::UnitZ()));
      cube.name = "cube";
      const BodyId c = w.add_body(cube);
      for (int i = 0; i < 1500; ++i) w.step(kDt);  // 0.3 s
      // Inside the inner volume (in the opening frame: resting on the floor, inner_depth below the
      // rim, within the radius / half extents), at rest, and the container still where it was.
      const Vector3d p = opening.rotation.transpose() * (w.center_of_mass(c) - opening.translation);
      CAPTURE(p.transpose(), rc.inner_radius, rc.inner_half_extents.transpose(), rc.inner_depth);
      CHECK(p.z() - half == Approx(-rc.inner_depth).margin(3e-3));  // on the receptacle's floor
      if (rc.inner_radius > 0) {
        CHECK(p.head<2>().norm() < rc.inner_radius);
      } else {
        CHECK(std::abs(p.x()) < rc.inner_half_extents.x());
        CHECK(std::abs(p.y()) < rc.inner_half_extents.y());
      }
      CHECK(w.linear_velocity(c).norm() < 0.01);
      CHECK(w.angular_velocity(c).norm() < 0.1);
      CHECK((w.position(container) - place.translation).norm() < 0.005);
    }
  }
  CHECK(containers >= 6 * 7);
}

}  // namespace test_asset_grasps
