// Tests of the procedurally generated assets of the "ManiSoft" benchmark (paper section 3.3):
// catalogue sizes, unique ids, closed visual meshes, visual/collision volume agreement, physically
// valid mass properties, graspable masses and widths, grasp frames, determinism.
#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>

#include <array>
#include <map>
#include <set>
#include <tuple>

#include "manisoft/assets/asset_view.hpp"
#include "manisoft/assets/catalog.hpp"

namespace test_assets {  // per-file namespace: the group's tests build as one unity translation unit

using namespace manisoft;
using namespace manisoft::assets;

namespace {

// Each undirected edge (vertices welded by exact float position) is used by exactly two triangles,
// once in each direction (consistent orientation).
bool closed_and_oriented(const render::Mesh& m) {
  using Key = std::tuple<float, float, float>;
  std::map<Key, int> weld;
  std::vector<int> id(m.positions.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const Key k{m.positions[i].x(), m.positions[i].y(), m.positions[i].z()};
    id[i] = weld.emplace(k, static_cast<int>(weld.size())).first->second;
  }
  std::map<std::pair<int, int>, int> directed;
  for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const std::array<int, 3> v{id[m.indices[t]], id[m.indices[t + 1]], id[m.indices[t + 2]]};
    for (int e = 0; e < 3; ++e) {
      const int a = v[static_cast<std::size_t>(e)], b = v[static_cast<std::size_t>((e + 1) % 3)];
      if (a == b) continue;  // degenerate (cap centre) edges do not occur, but be safe
      ++directed[{a, b}];
    }
  }
  for (const auto& [e, n] : directed) {
    if (n != 1) return false;
    const auto it = directed.find({e.second, e.first});
    if (it == directed.end() || it->second != 1) return false;
  }
  return true;
}

std::vector<Asset> all_assets() {
  auto a = object_catalog();
  auto b = obstacle_catalog();
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

}  // namespace

TEST_CASE("catalogue sizes and unique ids", "[assets]") {
  const auto objects = object_catalog();
  const auto obstacles = obstacle_catalog();
  std::set<std::string> ocat, bcat, ids;
  for (const auto& a : objects) ocat.insert(a.category), ids.insert(a.id);
  for (const auto& a : obstacles) bcat.insert(a.category), ids.insert(a.id);
  CHECK(ocat.size() >= 17);
  CHECK(objects.size() >= 109);
  CHECK(bcat.size() >= 35);
  CHECK(obstacles.size() >= 154);
  CHECK(ids.size() == objects.size() + obstacles.size());
}

TEST_CASE("lathe mesh volume matches the analytic polygonal lathe", "[assets]") {
  const std::vector<ProfilePoint> p{{0.03, 0}, {0.03, 0.15}, {0.012, 0.2}, {0.012, 0.22}};
  const auto m = make_lathe_mesh(p, 32);
  CHECK(closed_and_oriented(m));
  CHECK(mesh_volume(m) == Approx(lathe_volume(p, 32)).epsilon(1e-5));
  for (const auto& n : m.normals) CHECK(n.norm() == Approx(1.0f).epsilon(1e-5));
}

// No kind is excluded: every visual part is a closed solid (lathe or box).
TEST_CASE("visual parts are closed and their volume matches the collision volume", "[assets]") {
  for (const auto& a : all_assets()) {
    INFO(a.id);
    double vis = 0;
    for (const auto& part : a.visual) {
      REQUIRE(closed_and_oriented(part.mesh));
      REQUIRE(part.mesh.normals.size() == part.mesh.positions.size());
      REQUIRE(part.mesh.uvs.size() == part.mesh.positions.size());
      vis += mesh_volume(part.mesh);
    }
    const double col = geometry::shape_volume(a.collision);
    REQUIRE(vis > 0);
    CHECK(std::abs(vis - col) <= 0.05 * vis);
  }
}

TEST_CASE("mass properties are physical", "[assets]") {
  for (const auto& a : all_assets()) {
    INFO(a.id);
    REQUIRE(a.mass > 0);
    CHECK((a.inertia - a.inertia.transpose()).norm() <= 1e-12 * a.inertia.norm());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(a.inertia);
    const Eigen::Vector3d l = es.eigenvalues();
    CHECK(l.minCoeff() > 0);
    CHECK(l(0) + l(1) >= l(2) * (1 - 1e-9));
    CHECK(l(0) + l(2) >= l(1) * (1 - 1e-9));
    CHECK(l(1) + l(2) >= l(0) * (1 - 1e-9));
    const Eigen::Vector3d d = (a.center_of_mass - a.bounding_center).cwiseAbs();
    CHECK((d.array() <= a.bounding_half_extents.array() + 1e-12).all());
    CHECK(!a.resting_poses.empty());
    CHECK(a.resting_poses.front().name == "upright");
  }
}

TEST_CASE("graspable objects: mass, width and finger clearance", "[assets]") {
  const double open_width = 0.10, palm = 0.05, finger = 0.07;
  for (const auto& a : object_catalog()) {
    INFO(a.id);
    CHECK(a.mass <= 0.3);
    if (a.grasps.empty()) {  // only a container wider than the gripper opens (a basket)
      CHECK(!a.receptacles.empty());
      CHECK(2 * a.bounding_half_extents.head<2>().minCoeff() > open_width);
      continue;
    }
    for (const auto& g : a.grasps) {
      CHECK(g.width < open_width);
      CHECK(g.width <= 0.085 + 1e-12);
      CHECK(g.grasp.rotation.col(0).isApprox(Eigen::Vector3d(1, 0, 0)));
      CHECK(g.grasp.rotation.col(2).isApprox(Eigen::Vector3d(0, 0, -1)));
      CHECK((g.approach.translation - g.grasp.translation).isApprox(Eigen::Vector3d(0, 0, 0.10)));
      CHECK((g.lift.translation - g.grasp.translation).isApprox(Eigen::Vector3d(0, 0, 0.15)));
      // Collision extent along the closing axis (x) over the fingers' height range.
      const double top = a.bounding_center.z() + a.bounding_half_extents.z();
      const double finger_top = g.grasp.translation.z() - palm;
      CHECK(finger_top >= top - 1e-12);  // the palm clears the object
      CHECK(finger_top - finger < top);  // the fingers reach the object's upper part
      const auto& comp = std::get<geometry::Compound<double>>(a.collision);
      double half_x = 0;
      for (const auto& part : comp.parts) {
        if (const auto* c = std::get_if<geometry::Cylinder<double>>(&part.shape)) half_x = std::max(half_x, c->radius);
        if (const auto* b = std::get_if<geometry::Box<double>>(&part.shape)) half_x = std::max(half_x, b->half_extents.x());
      }
      CHECK(2 * half_x <= open_width);
      CHECK(std::abs(g.grasp.translation.x()) + half_x <= 0.5 * open_width);
    }
  }
}

TEST_CASE("containers have receptacles inside their bounds", "[assets]") {
  int n = 0;
  for (const auto& a : object_catalog()) {
    for (const auto& r : a.receptacles) {
      INFO(a.id);
      ++n;
      CHECK((r.inner_radius > 0 || (r.inner_half_extents.array() > 0).all()));
      CHECK(r.inner_depth > 0);
      CHECK(r.placement.translation.z() == Approx(r.opening.translation.z() - r.inner_depth));
    }
  }
  CHECK(n > 0);
}

TEST_CASE("catalogue is deterministic", "[assets]") {
  const auto a = all_assets();
  const auto b = all_assets();
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    REQUIRE(a[i].id == b[i].id);
    REQUIRE(a[i].visual.size() == b[i].visual.size());
    for (std::size_t k = 0; k < a[i].visual.size(); ++k) {
      CHECK(a[i].visual[k].mesh.positions == b[i].visual[k].mesh.positions);
      CHECK(a[i].visual[k].mesh.indices == b[i].visual[k].mesh.indices);
    }
    CHECK(a[i].mass == b[i].mass);
  }
}

// The contact sheet's framing (asset_view.hpp): every corner of every asset's bounding box
// projects inside its tile, and the box is not a speck (its projection spans at least a third
// of the tile).
TEST_CASE("asset views frame the whole bounding box", "[assets]") {
  AssetViewOptions opt;
  opt.width = 160;
  opt.height = 120;
  for (const auto& a : all_assets()) {
    INFO(a.id);
    const auto model = render::camera_model(frame_asset(a, opt));
    double umin = 1e9, umax = -1e9, vmin = 1e9, vmax = -1e9;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d corner =
          a.bounding_center + Eigen::Vector3d(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1).cwiseProduct(a.bounding_half_extents);
      const Eigen::Vector2d uv = model.project(corner);
      umin = std::min(umin, uv.x()), umax = std::max(umax, uv.x());
      vmin = std::min(vmin, uv.y()), vmax = std::max(vmax, uv.y());
    }
    CHECK(umin >= 0);
    CHECK(vmin >= 0);
    CHECK(umax <= opt.width - 1);
    CHECK(vmax <= opt.height - 1);
    CHECK(std::max(umax - umin, vmax - vmin) > opt.height / 3.0);
  }
  render::SceneDescription scene;
  render::FrameState frame;
  const auto objects = object_catalog();
  asset_scene(objects.front(), opt, scene, frame, 7);
  CHECK(scene.instances.size() == objects.front().visual.size() + 1);  // + the ground slab
  CHECK(frame.instance_poses.size() == scene.instances.size());
  CHECK(scene.instances.front().object_id == 7);
  Asset flat = objects.front();
  flat.bounding_half_extents.setZero();
  CHECK_THROWS_AS(frame_asset(flat, opt), manisoft::Error);
}

}  // namespace test_assets
