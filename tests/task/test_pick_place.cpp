// The tabletop pick and place on the task layer (include/manisoft/task/pick_place.hpp): the
// scene draw against hand-computed geometry, the catalogue's mass override, and expert episodes
// within the tracker's bounds (horizon, node speed, path straightness), bit for bit repeatable.
#include <catch2/catch.hpp>

#include <cmath>

#include "manisoft/task/pick_place.hpp"

namespace test_pick_place {  // per-file namespace: the group's tests build as one unity translation unit

namespace task = manisoft::task;
using manisoft::scene::AssetLibrary;
using manisoft::scene::SceneValidator;

TEST_CASE("pick and place: the object rests on the table as drawn and its mass can be set", "[tasks][pick_place]") {
  const AssetLibrary library(task::pick_place_catalog(task::PickPlaceObject::cube, 0.3));
  const auto& cube = library.get(task::pick_place_asset(task::PickPlaceObject::cube), "test");
  const AssetLibrary catalogue_library;
  const auto& catalogue = catalogue_library.get(cube.id, "test");
  CHECK(cube.mass == 0.3);
  CHECK((cube.inertia - catalogue.inertia * (0.3 / catalogue.mass)).norm() < 1e-15);
  CHECK_THROWS_WITH(task::pick_place_catalog(task::PickPlaceObject::cube, -1), Catch::Contains("-1"));
  // The lowest corner of the posed bounding box touches the table top (0.75 m), the object upright.
  for (const auto o : {task::PickPlaceObject::cube, task::PickPlaceObject::can}) {
    const auto& a = library.get(task::pick_place_asset(o), "test");
    const auto pose = task::pick_place_pose(a, Eigen::Vector2d(0.4, -0.1), 0.3, 0.75);
    double lowest = 1e9;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d corner = a.bounding_center + Eigen::Vector3d(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1).cwiseProduct(a.bounding_half_extents);
      lowest = std::min(lowest, pose.act(corner).z());
    }
    CAPTURE(a.id);
    CHECK(std::abs(lowest - 0.75) < 1e-12);
    CHECK(std::abs(pose.rotation.col(2).z() - 1.0) < 1e-15);
    CHECK((pose.rotation.col(0) - Eigen::Vector3d(std::cos(0.3), std::sin(0.3), 0)).norm() < 1e-15);
  }
}

TEST_CASE("pick and place: expert episodes succeed within the tracker's bounds, deterministically", "[tasks][pick_place][expert]") {
  const AssetLibrary library;
  SceneValidator validator(library);
  task::TaskEnv env(library, task::pick_place_env_config()), other(library, task::pick_place_env_config());
  task::Expert expert(env, task::pick_place_expert_config()), other_expert(other, task::pick_place_expert_config());
  for (std::uint64_t seed : {100000u, 100001u}) {
    const auto draw = task::draw_pick_place(validator, expert, env, task::PickPlaceObject::cube, seed);
    // 15-25 cm between the object and its place point, both in the reachable band
    const double distance = (draw.place - draw.object).head<2>().norm();
    CHECK((distance >= 0.15 && distance <= 0.25));
    CHECK((draw.place.x() >= 0.30 && draw.place.x() <= 0.62 && std::abs(draw.place.y()) <= 0.25));
    const auto r = task::run_pick_place(env, expert, draw);
    CAPTURE(seed, r.failure, r.steps, r.max_node_speed, r.max_path_ratio, r.place_error);
    CHECK(r.success);
    CHECK(r.steps <= 1500);
    CHECK(r.max_node_speed < 1.5);
    CHECK(r.max_path_ratio <= 1.5);
    CHECK(r.place_error < 0.01);  // the success bound is 2 cm
    CHECK(r.grasp_step > 0);
    CHECK(r.release_step > r.grasp_step);
    // The same seed in another environment (and after other episodes) gives the same episode, bit for bit.
    const auto again = task::run_pick_place(other, other_expert, task::draw_pick_place(validator, other_expert, other, task::PickPlaceObject::cube, seed));
    CHECK(again.steps == r.steps);
    CHECK(again.place_error == r.place_error);
    CHECK(again.max_node_speed == r.max_node_speed);
  }
}

}  // namespace test_pick_place
