// The six MuJoCo anchor scenes (shared/reference/mujoco/anchor_scenes.mjcf.txt) rebuilt with
// manisoft::rigid::RigidWorld: same sizes, densities, friction 0.5, initial poses, dt = 2e-4 s, plus the
// scene outcome measures of the reference tables (xy drift, sinking, tilt, ejection). Used by
// bench_rigid and the rigid-world tests.
#pragma once

#include "manisoft/geometry/compound_builders.hpp"
#include "manisoft/rigid/rigid_world.hpp"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace manisoft::scenes {

inline double deg(double d) { return d * std::numbers::pi / 180.0; }

/// MuJoCo's default euler sequence "xyz" (intrinsic): R = Rx(a) Ry(b) Rz(c), degrees.
inline Eigen::Quaterniond euler_xyz(double a, double b, double c) {
  return Eigen::AngleAxisd(deg(a), Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(deg(b), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(deg(c), Eigen::Vector3d::UnitZ());
}

struct Scene {
  std::string name;
  std::vector<rigid::BodyId> bodies;  ///< the dynamic bodies to watch
  std::vector<std::string> names;
};

inline rigid::BodyId add(rigid::RigidWorld& w, geometry::Shape<double> shape, Eigen::Vector3d pos, double density = 800,
                  Eigen::Quaterniond q = Eigen::Quaterniond::Identity(), std::string name = {}) {
  rigid::RigidBodyDesc d;
  d.shape = std::move(shape);
  d.density = density;
  d.position = pos;
  d.orientation = q;
  d.friction = 0.5;
  d.name = std::move(name);
  return w.add_body(d);
}

inline rigid::BodyId add_table(rigid::RigidWorld& w, double rolling_resistance = 0) {
  rigid::RigidBodyDesc d;
  d.rolling_resistance = rolling_resistance;
  d.shape = geometry::Box<double>{Eigen::Vector3d(0.6, 0.4, 0.02)};
  d.position = {0, 0, -0.02};
  d.is_static = true;
  d.friction = 0.5;
  d.name = "table";
  return w.add_body(d);
}

inline geometry::Box<double> box(double x, double y, double z) { return geometry::Box<double>{Eigen::Vector3d(x, y, z)}; }

/// S1..S6 (S5a = 20 degree incline, S5b = 30 degree incline). Returns the watched bodies.
inline Scene build(rigid::RigidWorld& w, const std::string& name) {
  Scene s;
  s.name = name;
  auto watch = [&](rigid::BodyId id, const std::string& n) { s.bodies.push_back(id); s.names.push_back(n); };
  if (name == "S1") {
    add_table(w);
    watch(add(w, box(0.025, 0.025, 0.025), {0, 0, 0.025}), "cube");
  } else if (name == "S2") {
    add_table(w);
    for (int k = 0; k < 5; ++k) watch(add(w, box(0.03, 0.03, 0.02), {0, 0, 0.02 + 0.04 * k}), "box" + std::to_string(k));
  } else if (name == "S3") {
    add_table(w);
    for (int k = 0; k < 3; ++k) watch(add(w, geometry::Cylinder<double>{0.03, 0.02}, {0, 0, 0.02 + 0.04 * k}), "cyl" + std::to_string(k));
  } else if (name == "S4") {
    add_table(w);
    watch(add(w, box(0.04, 0.03, 0.025), {-0.4, -0.2, 0.025}), "boxA");
    watch(add(w, box(0.05, 0.05, 0.05), {-0.2, -0.2, 0.05}, 500, euler_xyz(0, 0, 30)), "boxB");
    watch(add(w, geometry::Cylinder<double>{0.03, 0.05}, {0, -0.2, 0.05}), "cylA");
    watch(add(w, geometry::Cylinder<double>{0.04, 0.02}, {0.2, -0.2, 0.02}, 1000), "cylB");
    watch(add(w, geometry::Sphere<double>{0.03}, {0.4, -0.2, 0.03}), "sphA");
    watch(add(w, geometry::Sphere<double>{0.05}, {-0.3, 0.15, 0.05}, 500), "sphB");
    watch(add(w, geometry::Capsule<double>{0.02, 0.06}, {0, 0.15, 0.02}, 800, euler_xyz(0, 90, 0)), "capA");
    watch(add(w, geometry::Capsule<double>{0.025, 0.04}, {0.3, 0.15, 0.025}, 1000, euler_xyz(90, 0, 45)), "capB");
  } else if (name == "S5a" || name == "S5b") {
    const bool steep = name == "S5b";
    const double angle = steep ? 30 : 20;
    rigid::RigidBodyDesc d;
    d.shape = box(25, 0.5, 0.05);
    d.position = steep ? Eigen::Vector3d(-0.025, 0, -0.043301270) : Eigen::Vector3d(-0.017101007, 0, -0.046984631);
    d.orientation = euler_xyz(0, angle, 0);
    d.is_static = true;
    d.friction = 0.5;
    d.name = "incline";
    w.add_body(d);
    const Eigen::Vector3d p = steep ? Eigen::Vector3d(-17.308008, 0, 10.021651) : Eigen::Vector3d(0.008551, 0, 0.023492);
    watch(add(w, box(0.05, 0.05, 0.025), p, 800, euler_xyz(0, angle, 0)), "block");
  } else if (name == "S6") {
    add_table(w);
    const rigid::BodyId id = add(w, box(0.05, 0.05, 0.025), {-0.3, 0, 0.025});
    w.set_velocity(id, {1, 0, 0}, {0, 0, 0});
    watch(id, "slider");
  } else {
    manisoft::detail::fail("unknown scene '", name, "'");
  }
  return s;
}

/// Outcome of a resting scene, as in the MuJoCo tables.
struct Outcome {
  double max_xy_drift{0};   ///< m, largest horizontal displacement of any watched body
  double max_sink{0};       ///< m, largest downward displacement (positive = sank)
  double max_rise{0};       ///< m, largest upward displacement (a body popping out of contact)
  double max_tilt_deg{0};
  int ejected{0};           ///< bodies that left the table or fell below it
  std::string worst;
};

struct Tracker {
  std::vector<Eigen::Vector3d> start;
  std::vector<Eigen::Quaterniond> start_q;
  Outcome out;

  void begin(const rigid::RigidWorld& w, const Scene& s) {
    start.clear();
    start_q.clear();
    for (auto id : s.bodies) { start.push_back(w.position(id)); start_q.push_back(w.orientation(id)); }
    out = {};
  }
  void sample(const rigid::RigidWorld& w, const Scene& s) {
    for (std::size_t i = 0; i < s.bodies.size(); ++i) {
      const Eigen::Vector3d d = w.position(s.bodies[i]) - start[i];
      const double xy = std::hypot(d.x(), d.y());
      if (xy > out.max_xy_drift) { out.max_xy_drift = xy; out.worst = s.names[i]; }
      out.max_sink = std::max(out.max_sink, -d.z());
      out.max_rise = std::max(out.max_rise, d.z());
      out.max_tilt_deg = std::max(out.max_tilt_deg, w.orientation(s.bodies[i]).angularDistance(start_q[i]) * 180 / std::numbers::pi);
    }
  }
  void finish(const rigid::RigidWorld& w, const Scene& s) {
    for (auto id : s.bodies) {
      const Eigen::Vector3d p = w.position(id);
      if (p.z() < -0.05 || std::abs(p.x()) > 0.6 || std::abs(p.y()) > 0.4) ++out.ejected;
    }
  }
};

}  // namespace manisoft::scenes
