// The five tasks' success predicates (include/manisoft/task/: coll, aln, stk, arr, ovr) on hand-built states:
// each holds where the definition says it must, and fails just outside every tolerance, while an
// object is still held or moving, and for the wrong order or side.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "manisoft/task/registry.hpp"

namespace test_success {  // per-file namespace: the group's tests build as one unity translation unit

namespace {

namespace task = manisoft::task;
constexpr double kPi = std::numbers::pi;
using Eigen::Vector3d;

Eigen::Matrix3d yaw(double angle) { return Eigen::AngleAxisd(angle, Vector3d::UnitZ()).toRotationMatrix(); }

task::ObjectState object_at(const Vector3d& com) {
  task::ObjectState o;
  o.pose.translation = com;
  o.center_of_mass = com;
  return o;
}

void set_contact(std::vector<task::ObjectState>& objects, int a, int b) {
  objects[static_cast<std::size_t>(a)].touching |= std::uint64_t{1} << b;
  objects[static_cast<std::size_t>(b)].touching |= std::uint64_t{1} << a;
}

task::Snapshot snap(const std::vector<task::ObjectState>& objects, bool open = true) { return {objects, open}; }

}  // namespace

TEST_CASE("COLL: centre of mass inside the receptacle, touching it and not the table, released, at rest", "[tasks]") {
  // A round receptacle: opening 0.10 m above the container's origin, radius 6 cm, depth 8 cm.
  manisoft::assets::Receptacle receptacle;
  receptacle.opening.translation = Vector3d(0, 0, 0.10);
  receptacle.inner_radius = 0.06;
  receptacle.inner_depth = 0.08;
  // The container stands on the table turned 30 degrees; points are given in the opening frame.
  task::ObjectState container = object_at(Vector3d(0.5, 0.1, 0.75));
  container.pose.rotation = yaw(30 * kPi / 180);
  container.touches_table = true;
  const auto world_of = [&](const Vector3d& in_opening) {
    return container.pose.act(receptacle.opening.act(in_opening));
  };
  std::vector<task::ObjectState> objects{object_at(world_of(Vector3d(0.03, 0.0, -0.05))), container};
  set_contact(objects, 0, 1);
  CHECK(task::collected(snap(objects), 0, 1, receptacle));

  SECTION("radially just outside, or above the rim, or below the floor") {
    // 0.0605 m along the opening's x: the rotation by 30 degrees must be undone to see it.
    objects[0].center_of_mass = world_of(Vector3d(0.0605, 0, -0.05));
    CHECK_FALSE(task::collected(snap(objects), 0, 1, receptacle));
    objects[0].center_of_mass = world_of(Vector3d(0.0595 * std::cos(1.0), 0.0595 * std::sin(1.0), -0.05));
    CHECK(task::collected(snap(objects), 0, 1, receptacle));
    objects[0].center_of_mass = world_of(Vector3d(0, 0, 0.002));
    CHECK_FALSE(task::collected(snap(objects), 0, 1, receptacle));
    task::Tolerances tol;
    tol.coll_above_rim = 0.005;
    CHECK(task::collected(snap(objects), 0, 1, receptacle, tol));
    objects[0].center_of_mass = world_of(Vector3d(0, 0, -0.081));
    CHECK_FALSE(task::collected(snap(objects), 0, 1, receptacle));
  }
  SECTION("held, gripper closed, moving, or touching the table") {
    objects[0].held = true;
    CHECK_FALSE(task::collected(snap(objects), 0, 1, receptacle));
    objects[0].held = false;
    CHECK_FALSE(task::collected(snap(objects, false), 0, 1, receptacle));
    objects[0].linear_velocity = Vector3d(0, 0.0101, 0);
    CHECK_FALSE(task::collected(snap(objects), 0, 1, receptacle));
    objects[0].linear_velocity = Vector3d(0, 0.0099, 0);
    CHECK(task::collected(snap(objects), 0, 1, receptacle));
    objects[1].angular_velocity = Vector3d(0.11, 0, 0);  // the container still rocking
    CHECK_FALSE(task::collected(snap(objects), 0, 1, receptacle));
    objects[1].angular_velocity.setZero();
    objects[0].touches_table = true;
    CHECK_FALSE(task::collected(snap(objects), 0, 1, receptacle));
  }
  SECTION("not touching the container") {
    objects[0].touching = 0;
    CHECK_FALSE(task::collected(snap(objects), 0, 1, receptacle));
  }
  SECTION("a box-shaped receptacle") {
    receptacle.inner_radius = 0;
    receptacle.inner_half_extents = Eigen::Vector2d(0.10, 0.04);
    objects[0].center_of_mass = world_of(Vector3d(0.095, -0.035, -0.05));
    CHECK(task::collected(snap(objects), 0, 1, receptacle));
    objects[0].center_of_mass = world_of(Vector3d(0.095, -0.041, -0.05));
    CHECK_FALSE(task::collected(snap(objects), 0, 1, receptacle));
  }
  SECTION("each failing state names the one condition it breaks") {
    const task::Coll::Goal goal{0, 1, receptacle};
    const auto unmet = [&](bool open = true) { return task::Coll::evaluate(snap(objects, open), goal).unmet(); };
    CHECK(unmet().empty());
    objects[0].held = true;
    CHECK(unmet(false) == "released");
    objects[0].held = false;
    objects[0].touches_table = true;
    CHECK(unmet() == "off_table");
    objects[0].touches_table = false;
    objects[0].center_of_mass = world_of(Vector3d(0, 0, -0.081));
    objects[0].touching = 0;
    CHECK(unmet() == "inside, touching_container");
    objects[1].angular_velocity = Vector3d(0.11, 0, 0);
    CHECK(unmet() == "inside, touching_container, at_rest");
    // At the start of an episode only the position is judged: already inside is no task.
    CHECK_FALSE(task::Coll::holds_at_start(task::Coll::evaluate(snap(objects), goal)));
    objects[0].center_of_mass = world_of(Vector3d(0.03, 0.0, -0.05));
    CHECK(task::Coll::holds_at_start(task::Coll::evaluate(snap(objects), goal)));
  }
  CHECK_THROWS_WITH(task::collected(snap(objects), 0, 2, receptacle), Catch::Contains("object index 2 is out of range"));
}

TEST_CASE("registry: every task by name, its conditions as its predicate lists them", "[tasks]") {
  namespace scene = manisoft::scene;
  REQUIRE(scene::all_tasks.size() == 5);
  const std::array<const char*, 5> names{"COLL", "ALN", "STK", "ARR", "OVR"};
  for (std::size_t k = 0; k < scene::all_tasks.size(); ++k) {
    const task::TaskInfo info = task::task_info(scene::all_tasks[k]);
    CHECK(info.name == names[k]);
    CHECK(scene::parse_task(names[k]) == scene::all_tasks[k]);
    CHECK_FALSE(info.summary.empty());
    CHECK(info.conditions.back() == "at_rest");
  }
  // The names evaluate() reports are the ones the registry lists, in order (STK on a hand-built
  // two-item stack whose top item still moves).
  std::vector<task::ObjectState> objects{object_at(Vector3d(0.5, 0, 0.76)), object_at(Vector3d(0.5, 0.01, 0.79))};
  objects[0].touches_table = true;
  set_contact(objects, 0, 1);
  objects[1].linear_velocity = Vector3d(0, 0, 0.5);
  const std::array<int, 2> items{0, 1};
  const task::Conditions c = task::Stk::evaluate(snap(objects), items);
  std::vector<std::string_view> reported;
  for (const auto& condition : c) reported.push_back(condition.name);
  CHECK(reported == task::task_info(scene::Task::stk).conditions);
  CHECK(c.unmet() == "at_rest");
  // The episode's target object: the goal's object, the top of the stack, the first placed object.
  scene::SceneSpec spec;
  spec.task = scene::Task::stk;
  spec.goal.items = {2, 0, 1};
  CHECK(task::target_object(spec) == 1);
  spec.task = scene::Task::aln;
  spec.goal.object = 3;
  CHECK(task::target_object(spec) == 3);
  spec.task = scene::Task::arr;
  spec.goal.relations.push_back(scene::Relation{scene::Relation::Kind::left_of, {4}, {0}, {}});
  CHECK(task::target_object(spec) == 4);
}

TEST_CASE("ALN: position within 2 cm, orientation within 0.2 rad modulo the object's symmetry", "[tasks]") {
  manisoft::math::Pose<double> goal;
  goal.translation = Vector3d(0.4, -0.1, 0.75);
  goal.rotation = yaw(0.5);
  std::vector<task::ObjectState> objects{object_at(goal.translation + Vector3d(0.012, -0.015, 0.0))};  // 1.92 cm off
  objects[0].pose.rotation = goal.rotation * yaw(0.19);
  CHECK(task::aligned(snap(objects), 0, goal, task::Symmetry::none()));
  objects[0].pose.translation = goal.translation + Vector3d(0.012, -0.0165, 0.0);  // 2.04 cm off
  CHECK_FALSE(task::aligned(snap(objects), 0, goal, task::Symmetry::none()));
  objects[0].pose.translation = goal.translation;

  // Yaw 0.21 rad: too far for an asymmetric object (a shoe), irrelevant for a bottle.
  objects[0].pose.rotation = goal.rotation * yaw(0.21);
  CHECK_FALSE(task::aligned(snap(objects), 0, goal, task::Symmetry::none()));
  CHECK(task::aligned(snap(objects), 0, goal, task::Symmetry::axial()));
  // A bottle tilted by 0.21 rad fails even with axial symmetry; 0.19 passes.
  const Eigen::Matrix3d tilt_over = Eigen::AngleAxisd(0.21, Vector3d::UnitX()).toRotationMatrix();
  objects[0].pose.rotation = goal.rotation * yaw(2.0) * tilt_over;
  CHECK_FALSE(task::aligned(snap(objects), 0, goal, task::Symmetry::axial()));
  objects[0].pose.rotation = goal.rotation * yaw(2.0) * Eigen::AngleAxisd(0.19, Vector3d::UnitX()).toRotationMatrix();
  CHECK(task::aligned(snap(objects), 0, goal, task::Symmetry::axial()));
  // A box turned by a half turn (+0.1 rad) is aligned 2-fold, not 1-fold; a quarter turn 4-fold only.
  objects[0].pose.rotation = goal.rotation * yaw(kPi + 0.1);
  CHECK(task::aligned(snap(objects), 0, goal, task::Symmetry::discrete(2)));
  CHECK_FALSE(task::aligned(snap(objects), 0, goal, task::Symmetry::none()));
  objects[0].pose.rotation = goal.rotation * yaw(kPi / 2 - 0.1);
  CHECK_FALSE(task::aligned(snap(objects), 0, goal, task::Symmetry::discrete(2)));
  CHECK(task::aligned(snap(objects), 0, goal, task::Symmetry::discrete(4)));
  CHECK(task::orientation_error(goal.rotation * yaw(kPi / 2 - 0.1), goal.rotation, task::Symmetry::discrete(4)) ==
        Approx(0.1).margin(1e-9));

  objects[0].pose.rotation = goal.rotation;
  objects[0].held = true;
  CHECK_FALSE(task::aligned(snap(objects), 0, goal, task::Symmetry::none()));
  objects[0].held = false;
  objects[0].angular_velocity = Vector3d(0, 0, 0.15);
  CHECK_FALSE(task::aligned(snap(objects), 0, goal, task::Symmetry::none()));
}

TEST_CASE("OVR: position within 2 cm of the marker, upright within 0.2 rad at any yaw, released, at rest", "[tasks]") {
  const task::Ovr::Goal goal{0, Vector3d(0.45, 0.2, 0.75)};
  std::vector<task::ObjectState> objects{object_at(goal.position + Vector3d(0.012, -0.015, 0.0))};  // 1.92 cm off
  objects[0].pose.rotation = yaw(2.5);  // any yaw
  const auto unmet = [&](bool open = true) { return task::Ovr::evaluate(snap(objects, open), goal).unmet(); };
  CHECK(unmet().empty());
  CHECK(task::Ovr::holds_at_start(task::Ovr::evaluate(snap(objects), goal)));
  objects[0].pose.translation = goal.position + Vector3d(0.012, -0.0165, 0.0);  // 2.04 cm off
  CHECK(unmet() == "position");
  CHECK_FALSE(task::Ovr::holds_at_start(task::Ovr::evaluate(snap(objects), goal)));
  objects[0].pose.translation = goal.position + Vector3d(0, 0, 0.0199);  // height counts too
  CHECK(unmet().empty());
  objects[0].pose.translation = goal.position + Vector3d(0, 0, 0.0201);
  CHECK(unmet() == "position");
  objects[0].pose.translation = goal.position;
  // Tilted about a horizontal axis: 0.19 rad passes, 0.21 rad fails, whatever the yaw.
  const Vector3d axis = Vector3d(1, 1, 0).normalized();
  objects[0].pose.rotation = Eigen::AngleAxisd(0.19, axis).toRotationMatrix() * yaw(-1.0);
  CHECK(unmet().empty());
  objects[0].pose.rotation = Eigen::AngleAxisd(0.21, axis).toRotationMatrix() * yaw(-1.0);
  CHECK(unmet() == "upright");
  objects[0].pose.rotation = Eigen::AngleAxisd(kPi / 2, Vector3d::UnitY()).toRotationMatrix();  // lying on its side
  CHECK(unmet() == "upright");
  CHECK(task::Ovr::holds_at_start(task::Ovr::evaluate(snap(objects), goal)));  // at the marker: no task
  objects[0].pose.rotation = yaw(0.3);
  objects[0].held = true;
  CHECK(unmet() == "released");
  objects[0].held = false;
  CHECK(unmet(false) == "released");  // the gripper closed
  objects[0].linear_velocity = Vector3d(0, 0.011, 0);
  CHECK(unmet() == "at_rest");
  objects[0].linear_velocity = Vector3d(0, 0.009, 0);
  CHECK(unmet().empty());
  CHECK_THROWS_WITH(task::Ovr::evaluate(snap(objects), task::Ovr::Goal{1, goal.position}), Catch::Contains("object index 1 is out of range"));
  // The goal from a scene: the object and the obstacle between must exist.
  manisoft::scene::SceneSpec spec;
  spec.task = manisoft::scene::Task::ovr;
  spec.objects.resize(2);
  spec.obstacles.resize(1);
  spec.goal.object = 1;
  spec.goal.obstacle = 0;
  spec.goal.goal_pose.translation = goal.position;
  const manisoft::scene::AssetLibrary library;
  CHECK(task::Ovr::goal(spec, library).position == goal.position);
  CHECK(task::target_object(spec) == 1);
  spec.goal.obstacle = 1;
  CHECK_THROWS_WITH(task::Ovr::goal(spec, library), Catch::Contains("OVR goal: obstacle 1 is not one of the scene's 1 obstacles"));
  spec.goal.obstacle = 0;
  spec.goal.object = 2;
  CHECK_THROWS_WITH(task::Ovr::goal(spec, library), Catch::Contains("OVR goal: object 2 is not one of the scene's 2 objects"));
}

TEST_CASE("STK: largest to smallest, centred within 3 cm, each on the one below, released, at rest", "[tasks]") {
  // Three bowls, bottom first; centres of mass rise by 2 cm each (nested).
  std::vector<task::ObjectState> objects{object_at(Vector3d(0.5, 0, 0.78)), object_at(Vector3d(0.51, 0.01, 0.80)),
                                         object_at(Vector3d(0.52, -0.005, 0.82))};
  objects[0].touches_table = true;
  set_contact(objects, 0, 1);
  set_contact(objects, 1, 2);
  const std::array<int, 3> order{0, 1, 2};
  CHECK(task::stacked(snap(objects), order));

  SECTION("wrong order") {
    const std::array<int, 3> reversed{2, 1, 0};
    CHECK_FALSE(task::stacked(snap(objects), reversed));
  }
  SECTION("off-centre by just over 3 cm") {
    objects[2].center_of_mass = Vector3d(0.51 + 0.0301, 0.01, 0.82);
    CHECK_FALSE(task::stacked(snap(objects), order));
    objects[2].center_of_mass = Vector3d(0.51 + 0.0299, 0.01, 0.82);
    CHECK(task::stacked(snap(objects), order));
  }
  SECTION("the top item beside the stack on the table, or not touching the one below") {
    objects[2].touches_table = true;
    CHECK_FALSE(task::stacked(snap(objects), order));
    objects[2].touches_table = false;
    objects[2].touching = 0;
    objects[1].touching &= ~(std::uint64_t{1} << 2);
    CHECK_FALSE(task::stacked(snap(objects), order));
  }
  SECTION("still held, or the gripper closed, or wobbling") {
    objects[2].held = true;
    CHECK_FALSE(task::stacked(snap(objects), order));
    objects[2].held = false;
    CHECK_FALSE(task::stacked(snap(objects, false), order));
    objects[0].linear_velocity = Vector3d(0.02, 0, 0);
    CHECK_FALSE(task::stacked(snap(objects), order));
  }
  const std::array<int, 1> one{0};
  CHECK_THROWS_WITH(task::stacked(snap(objects), one), Catch::Contains("at least 2 items, got 1"));
}

TEST_CASE("ARR: relations in the viewer's words with their margins", "[tasks]") {
  // The viewer looks from +x: left is -y, in front is +x.
  std::vector<task::ObjectState> objects{object_at(Vector3d(0.5, -0.15, 0.8)), object_at(Vector3d(0.52, 0.0, 0.8)),
                                         object_at(Vector3d(0.5, 0.15, 0.8)), object_at(Vector3d(0.5, 0.30, 0.8))};
  using Kind = task::Relation::Kind;
  const auto relation = [](Kind kind, std::array<int, 4> who) {  // who[0] placed, then the references until -1
    task::Relation r;
    r.kind = kind;
    r.objects = {who[0]};
    for (std::size_t k = 1; k < who.size() && who[k] >= 0; ++k) r.references.push_back(who[k]);
    return r;
  };
  const auto holds = [&](Kind kind, std::array<int, 4> who) { return task::Arr::relation_holds(snap(objects), relation(kind, who)); };
  CHECK(holds(Kind::left_of, {0, 1, -1, -1}));   // 15 cm to the viewer's left, 2 cm across
  CHECK_FALSE(holds(Kind::right_of, {0, 1, -1, -1}));
  CHECK(holds(Kind::right_of, {1, 0, -1, -1}));
  CHECK_FALSE(holds(Kind::left_of, {0, 3, -1, -1}));  // 45 cm: beyond 30 cm
  CHECK_FALSE(holds(Kind::in_front_of, {1, 0, -1, -1}));  // 2 cm in front is too little
  CHECK(holds(Kind::between, {1, 0, 2, -1}));
  CHECK_FALSE(holds(Kind::between, {0, 1, 2, -1}));
  CHECK(holds(Kind::in_a_row, {0, 1, 2, 3}));
  CHECK(holds(Kind::next_to, {0, 1, -1, -1}));
  CHECK_FALSE(holds(Kind::next_to, {0, 2, -1, -1}));  // 30 cm apart

  objects[1].center_of_mass = Vector3d(0.5 + 0.031, 0.0, 0.8);  // 3.1 cm off the row's line
  CHECK_FALSE(holds(Kind::in_a_row, {0, 1, 2, 3}));
  objects[1].center_of_mass = Vector3d(0.5 + 0.029, 0.0, 0.8);
  CHECK(holds(Kind::in_a_row, {0, 1, 2, 3}));

  // In front / behind: along +x, at most 8 cm across.
  objects[0].center_of_mass = Vector3d(0.70, -0.075, 0.8);
  objects[1].center_of_mass = Vector3d(0.55, 0.0, 0.8);
  CHECK(holds(Kind::in_front_of, {0, 1, -1, -1}));
  CHECK(holds(Kind::behind, {1, 0, -1, -1}));
  objects[0].center_of_mass.y() = -0.085;
  CHECK_FALSE(holds(Kind::in_front_of, {0, 1, -1, -1}));

  // arranged(): relations hold and every named object is released and at rest.
  objects[0].center_of_mass = Vector3d(0.5, -0.15, 0.8);
  objects[1].center_of_mass = Vector3d(0.52, 0.0, 0.8);
  const std::array<task::Relation, 2> goal{relation(Kind::left_of, {0, 1, -1, -1}), relation(Kind::right_of, {2, 1, -1, -1})};
  CHECK(task::arranged(snap(objects), goal));
  objects[2].held = true;
  CHECK_FALSE(task::arranged(snap(objects), goal));
  objects[2].held = false;
  objects[3].linear_velocity = Vector3d(1, 0, 0);  // not named: does not matter
  CHECK(task::arranged(snap(objects), goal));

  CHECK_THROWS_WITH(holds(Kind::between, {0, 1, -1, -1}), Catch::Contains("between needs 3 objects, got 2"));
}

TEST_CASE("SuccessTracker: success once after the hold, and whether it holds at the end", "[tasks]") {
  task::SuccessTracker tracker(3);
  const std::array<bool, 8> holds{true, true, false, true, true, true, true, false};
  std::vector<long> reached;
  for (long step = 0; step < static_cast<long>(holds.size()); ++step)
    if (tracker.update(step, holds[static_cast<std::size_t>(step)])) reached.push_back(step);
  REQUIRE(reached.size() == 1);
  CHECK(reached[0] == 5);  // steps 3, 4, 5 in a row
  CHECK(tracker.succeeded());
  CHECK(tracker.first_success_step() == 5);
  CHECK_FALSE(tracker.holds_now());  // knocked over at the last step: success once, not at end
  CHECK_THROWS_WITH(task::SuccessTracker(0), Catch::Contains("hold_steps = 0"));
  CHECK(task::to_string(task::FailureReason::arm_hit_obstacle) == "arm_hit_obstacle");
}

}  // namespace test_success
