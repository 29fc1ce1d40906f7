// Mass properties of every shape against closed forms, the OBJ loader (a cube and a tetrahedron
// written to a temporary directory), malformed OBJ files, compounds (parallel-axis theorem) and
// refused body descriptions.
#include "manisoft/geometry/convex_polyhedron.hpp"
#include "manisoft/geometry/compound_builders.hpp"
#include "manisoft/geometry/obj_loader.hpp"
#include "manisoft/rigid/rigid_world.hpp"

#include <catch2/catch.hpp>

#include "../support/scratch_dir.hpp"

#include <filesystem>
#include <fstream>
#include <numbers>

namespace test_rigid_shapes {  // per-file namespace: the group's tests build as one unity translation unit

using namespace manisoft;
using namespace manisoft::geometry;
using namespace manisoft::rigid;
using Catch::Matchers::Contains;
using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

constexpr double kPi = std::numbers::pi;

std::filesystem::path temp_dir() {
  auto dir = manisoft::test::scratch_dir("manisoft_rigid_tests");
  std::filesystem::create_directories(dir);
  return dir;
}

std::string write_file(const std::string& name, const std::string& text) {
  const auto path = temp_dir() / name;
  std::ofstream(path) << text;
  return path.string();
}

const char* kCubeObj =
    "# unit cube centred at (1, 2, 3), quads\n"
    "v 0.5 1.5 2.5\nv 1.5 1.5 2.5\nv 1.5 2.5 2.5\nv 0.5 2.5 2.5\n"
    "v 0.5 1.5 3.5\nv 1.5 1.5 3.5\nv 1.5 2.5 3.5\nv 0.5 2.5 3.5\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

bool near(const Matrix3d& a, const Matrix3d& b, double tol) { return (a - b).cwiseAbs().maxCoeff() <= tol; }

}  // namespace

TEST_CASE("primitive mass properties match closed forms", "[world][mass]") {
  const double rho = 800;
  SECTION("box") {
    const auto mp = geometry::mass_properties(geometry::Box<double>{Vector3d(0.1, 0.2, 0.3)}, rho);
    const double m = rho * 0.2 * 0.4 * 0.6;
    CHECK(mp.mass == Approx(m).epsilon(1e-14));
    CHECK(mp.inertia(0, 0) == Approx(m / 12 * (0.16 + 0.36)).epsilon(1e-13));
    CHECK(mp.inertia(1, 1) == Approx(m / 12 * (0.04 + 0.36)).epsilon(1e-13));
    CHECK(mp.inertia(2, 2) == Approx(m / 12 * (0.04 + 0.16)).epsilon(1e-13));
  }
  SECTION("sphere") {
    const auto mp = geometry::mass_properties(geometry::Sphere<double>{0.05}, rho);
    const double m = rho * 4.0 / 3.0 * kPi * 1.25e-4;
    CHECK(mp.mass == Approx(m).epsilon(1e-14));
    CHECK(mp.inertia(1, 1) == Approx(0.4 * m * 0.0025).epsilon(1e-13));
  }
  SECTION("cylinder") {
    const auto mp = geometry::mass_properties(geometry::Cylinder<double>{0.03, 0.05}, rho);
    const double m = rho * kPi * 0.0009 * 0.1;
    CHECK(mp.mass == Approx(m).epsilon(1e-14));
    CHECK(mp.inertia(2, 2) == Approx(0.5 * m * 0.0009).epsilon(1e-13));
    CHECK(mp.inertia(0, 0) == Approx(m * (3 * 0.0009 + 0.01) / 12).epsilon(1e-13));
  }
  SECTION("capsule = cylinder + sphere, lateral inertia from the hemisphere formula") {
    const double r = 0.02, a = 0.06;
    const auto mp = geometry::mass_properties(geometry::Capsule<double>{r, a}, rho);
    const double mc = rho * kPi * r * r * 2 * a, ms = rho * 4.0 / 3.0 * kPi * r * r * r;
    CHECK(mp.mass == Approx(mc + ms).epsilon(1e-14));
    CHECK(mp.inertia(2, 2) == Approx(0.5 * mc * r * r + 0.4 * ms * r * r).epsilon(1e-13));
    // Independent check: integrate the lateral inertia numerically over slices along the axis.
    double lateral = 0;
    const int n = 200000;
    const double zmax = a + r, dz = 2 * zmax / n;
    for (int i = 0; i < n; ++i) {
      const double z = -zmax + (i + 0.5) * dz;
      const double ez = std::max(0.0, std::abs(z) - a);
      const double rr = r * r - ez * ez;  // slice radius squared
      const double dm = rho * kPi * rr * dz;
      lateral += dm * (rr / 4 + z * z);
    }
    CHECK(mp.inertia(0, 0) == Approx(lateral).epsilon(1e-6));
  }
}

TEST_CASE("convex meshes from OBJ: exact polyhedral mass properties", "[world][mass][obj]") {
  SECTION("cube with quad faces, off-origin") {
    const auto mesh = geometry::load_obj_convex_mesh(write_file("cube.obj", kCubeObj));
    CHECK(mesh.vertices.size() == 8);
    CHECK(mesh.triangles.size() == 12);
    const auto mp = geometry::mass_properties(mesh, 1000.0);
    CHECK(mp.mass == Approx(1000.0).epsilon(1e-12));
    CHECK((mp.center_of_mass - Vector3d(1, 2, 3)).norm() < 1e-12);
    CHECK(near(mp.inertia, Matrix3d::Identity() * 1000.0 / 6.0, 1e-10));
    const auto box = geometry::mass_properties(geometry::Box<double>{Vector3d::Constant(0.5)}, 1000.0);
    CHECK(near(mp.inertia, box.inertia, 1e-10));
    const auto poly = geometry::make_polyhedron(mesh, mp.center_of_mass);
    CHECK(poly.faces.size() == 6);  // coplanar triangles merged
    CHECK(poly.directions.size() == 3);
  }
  SECTION("tetrahedron, wound inside-out") {
    const auto mesh = geometry::load_obj_convex_mesh(write_file(
        "tetra.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n"));
    const auto mp = geometry::mass_properties(mesh, 600.0);
    // Unit right tetrahedron: V = 1/6, centroid (1/4)(1,1,1); about the origin
    // int x^2 = int xy... = 1/60 and 1/120: I_origin = rho [[1/30, -1/120, ...]]. Shift to the COM.
    const double m = 600.0 / 6.0;
    CHECK(mp.mass == Approx(m).epsilon(1e-12));
    CHECK((mp.center_of_mass - Vector3d::Constant(0.25)).norm() < 1e-12);
    Matrix3d c_origin;
    c_origin << 1.0 / 60, 1.0 / 120, 1.0 / 120, 1.0 / 120, 1.0 / 60, 1.0 / 120, 1.0 / 120, 1.0 / 120, 1.0 / 60;
    c_origin *= 600.0;
    const Vector3d com = Vector3d::Constant(0.25);
    const Matrix3d c_com = c_origin - m * com * com.transpose();
    const Matrix3d expected = c_com.trace() * Matrix3d::Identity() - c_com;
    CHECK(near(mp.inertia, expected, 1e-12));
    CHECK(mp.inertia(0, 0) == Approx(m * 3.0 / 40.0).epsilon(1e-12));  // unit right tetrahedron: 3m/40
  }
}

TEST_CASE("malformed OBJ files are refused with file and line", "[world][obj]") {
  const auto bad_vertex = write_file("bad_vertex.obj", "v 0 0 0\nv 1 0\nv 0 1 0\n");
  CHECK_THROWS_WITH(geometry::load_obj_convex_mesh(bad_vertex), Contains("bad_vertex.obj:2") && Contains("vertex"));
  const auto bad_index = write_file("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 9\n");
  CHECK_THROWS_WITH(geometry::load_obj_convex_mesh(bad_index), Contains("bad_index.obj:5") && Contains("9"));
  const auto bad_token = write_file("bad_token.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n");
  CHECK_THROWS_WITH(geometry::load_obj_convex_mesh(bad_token), Contains("bad_token.obj:4") && Contains("'x'"));
  const auto unknown = write_file("unknown.obj", "v 0 0 0\nbogus 1 2 3\n");
  CHECK_THROWS_WITH(geometry::load_obj_convex_mesh(unknown), Contains("unknown.obj:2") && Contains("bogus"));
  const auto too_small = write_file("flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  CHECK_THROWS_WITH(geometry::load_obj_convex_mesh(too_small), Contains("flat.obj") && Contains("at least 4"));
  CHECK_THROWS_WITH(geometry::load_obj_convex_mesh((temp_dir() / "missing.obj").string()), Contains("missing.obj"));
  // A non-convex (dented) solid is refused when it becomes a body.
  const auto dented = write_file(
      "dented.obj",
      "v 0 0 0\nv 2 0 0\nv 0 2 0\nv 0 0 2\nv 0.3 0.3 0.3\n"  // vertex 5 dents face 2-3-4 inward
      "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 5\nf 3 4 5\nf 4 2 5\n");
  rigid::RigidWorld world;
  rigid::RigidBodyDesc d;
  d.shape = geometry::load_obj_convex_mesh(dented);
  d.density = 500;
  CHECK_THROWS_WITH(world.add_body(d), Contains("dented.obj") && Contains("not convex"));
}

TEST_CASE("compound mass properties follow the parallel-axis theorem", "[world][mass][compound]") {
  // Two unit cubes side by side along x = one 2x1x1 box.
  geometry::Compound<double> c;
  c.parts.push_back({geometry::Box<double>{Vector3d::Constant(0.5)}, Vector3d(0.5, 0, 0), Eigen::Quaterniond::Identity()});
  c.parts.push_back({geometry::Box<double>{Vector3d::Constant(0.5)}, Vector3d(-0.5, 0, 0), Eigen::Quaterniond::Identity()});
  const auto mp = geometry::mass_properties(c, 100.0);
  const auto ref = geometry::mass_properties(geometry::Box<double>{Vector3d(1, 0.5, 0.5)}, 100.0);
  CHECK(mp.mass == Approx(ref.mass).epsilon(1e-14));
  CHECK(mp.center_of_mass.norm() < 1e-15);
  CHECK(near(mp.inertia, ref.inertia, 1e-12));
  // A rotated part: a box rotated 90 degrees about z swaps its x and y inertia.
  geometry::Compound<double> r;
  r.parts.push_back({geometry::Box<double>{Vector3d(0.3, 0.1, 0.2)}, Vector3d(0, 0, 1),
                     Eigen::Quaterniond(Eigen::AngleAxisd(kPi / 2, Vector3d::UnitZ()))});
  const auto rp = geometry::mass_properties(r, 100.0);
  const auto bp = geometry::mass_properties(geometry::Box<double>{Vector3d(0.1, 0.3, 0.2)}, 100.0);
  CHECK((rp.center_of_mass - Vector3d(0, 0, 1)).norm() < 1e-15);
  CHECK(near(rp.inertia, bp.inertia, 1e-12));
  // Vessels: symmetric about z, centre of mass on the axis, above the base.
  const auto bowl = geometry::mass_properties(geometry::make_bowl(), 800.0);
  CHECK(std::abs(bowl.center_of_mass.x()) < 1e-12);
  CHECK(std::abs(bowl.center_of_mass.y()) < 1e-12);
  CHECK(bowl.center_of_mass.z() > 0.002);
  CHECK(bowl.inertia(0, 0) == Approx(bowl.inertia(1, 1)).epsilon(1e-9));
  CHECK(geometry::mass_properties(geometry::make_bin(), 800.0).mass > 0);
  CHECK(geometry::mass_properties(geometry::make_plate(), 800.0).mass > 0);
  CHECK(geometry::mass_properties(geometry::make_cup(), 800.0).mass > 0);
}

TEST_CASE("bad body descriptions are refused naming the body and the value", "[world][input]") {
  rigid::RigidWorld world;
  rigid::RigidBodyDesc d;
  d.name = "crate";
  d.shape = geometry::Box<double>{Vector3d(0.1, 0.1, 0.1)};
  d.density = 0;
  CHECK_THROWS_WITH(world.add_body(d), Contains("crate") && Contains("density"));
  d.density = 500;
  d.friction = -0.1;
  CHECK_THROWS_WITH(world.add_body(d), Contains("crate") && Contains("friction"));
  d.friction = 0.5;
  d.restitution = 1.5;
  CHECK_THROWS_WITH(world.add_body(d), Contains("restitution"));
  d.restitution = 0;
  d.position.x() = std::nan("");
  CHECK_THROWS_WITH(world.add_body(d), Contains("crate") && Contains("finite"));
  d.position.x() = 0;
  d.shape = geometry::Sphere<double>{-1.0};
  CHECK_THROWS_WITH(world.add_body(d), Contains("crate") && Contains("radius"));
  d.shape = geometry::Box<double>{Vector3d(0.1, 0.1, 0.1)};
  const rigid::BodyId id = world.add_body(d);
  CHECK_THROWS_WITH(world.step(0.0), Contains("dt"));
  CHECK_THROWS_WITH(world.add_force(id, Vector3d(std::nan(""), 0, 0)), Contains("crate") && Contains("not finite"));
  CHECK_THROWS_WITH(world.add_force(7, Vector3d::Zero()), Contains("out of range"));
  rigid::RigidWorldSettings bad;
  bad.contact_margin = -1;
  CHECK_THROWS_WITH(RigidWorld(bad), Contains("contact_margin"));
}

}  // namespace test_rigid_shapes
