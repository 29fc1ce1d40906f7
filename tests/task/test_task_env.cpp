// The task environment and the expert (include/manisoft/task/task_env.hpp, expert.hpp): the
// predicate judged in the simulated world against hand-built outcomes (an object dropped into its
// container by gravity alone, a goal that holds before any action, an object dropped off the
// table, the horizon), refused input, determinism of a whole expert episode, and the expert on
// fixed sampled scenes.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <random>
#include <string>

#include "manisoft/scene/scene_sampler.hpp"
#include "manisoft/task/expert.hpp"
#include "manisoft/task/expert_config_json.hpp"
#include "manisoft/task/task_env.hpp"
#include "../support/scratch_dir.hpp"

namespace test_task_env {  // per-file namespace: the group's tests build as one unity translation unit

using Pose = manisoft::math::Pose<double>;
using manisoft::task::Expert;
using manisoft::task::FailureReason;
using manisoft::task::TaskEnv;
using namespace manisoft::scene;

namespace {

SceneSampler& sampler() {
  static SceneSampler s;
  return s;
}
TaskEnv& env() {
  static TaskEnv e(sampler().library());
  return e;
}
SceneSpec sample(Task t, std::uint64_t index) {
  SampleRequest q;
  q.task = t;
  q.setting = Setting::clean;
  q.index = index;
  return sampler().sample(q);
}

/// Runs `expert` on `e` from scene `s` for at most `max_steps` control steps (or until done);
/// `after_step`, when given, sees each step's outcome with the phase the expert acted in.
void run_expert(TaskEnv& e, Expert& expert, const SceneSpec& s, int max_steps = 100000,
                const std::function<void(manisoft::task::ExpertPhase)>& after_step = {}) {
  e.reset(s);
  expert.reset();
  TaskEnv::Array3 torques;
  int gripper = 0;
  for (int i = 0; i < max_steps && !e.done(); ++i) {
    expert.act(torques, gripper);
    const auto phase = expert.phase();
    e.step(torques, gripper);
    if (after_step) after_step(phase);
  }
}

/// Holds the arm at home (a copy of the executor that brought it there) until the episode ends.
void hold_home(TaskEnv& e, int max_steps = 100000) {
  TaskEnv::Executor hold = e.home_executor();
  auto observation = manisoft::control::make_arm_observation<double>(e.arm_model().rod.n_elements, e.config().observe_stride);
  TaskEnv::Array3 torques;
  for (int i = 0; i < max_steps && !e.done(); ++i) {
    manisoft::control::observe_arm(e.world(), e.home_pose(), observation);
    hold.act(observation, torques);
    e.step(torques, 0);
  }
}

/// The COLL scene of clean index 3 (a cup and a basket) with the cup moved to `cup`.
SceneSpec coll_with_cup_at(const Eigen::Vector3d& cup) {
  SceneSpec s = sample(Task::coll, 3);
  s.objects.at(static_cast<std::size_t>(s.goal.object)).pose.translation = cup;
  return s;
}
Pose container_placement(const SceneSpec& s, Pose* opening = nullptr) {
  const auto& c = s.objects.at(static_cast<std::size_t>(s.goal.container));
  const auto& rc = sampler().library().get(c.asset_id, "test").receptacles.at(0);
  if (opening) *opening = c.pose * rc.opening;
  return c.pose * rc.placement;
}

}  // namespace

TEST_CASE("COLL: a cup released over the basket's opening falls in and the episode succeeds", "[tasks][env]") {
  SceneSpec s = sample(Task::coll, 3);
  Pose opening;
  const Pose placement = container_placement(s, &opening);
  // The cup 2 cm above the rim, centred over the placement point: gravity alone puts it in.
  const Eigen::Vector3d start(placement.translation.x(), placement.translation.y(), opening.translation.z() + 0.02);
  s = coll_with_cup_at(start);
  TaskEnv& e = env();
  e.reset(s);
  REQUIRE_FALSE(e.done());
  hold_home(e);
  CHECK(e.info().success);
  CHECK(e.info().terminated);
  CHECK(e.conditions().all());
  CHECK(e.info().failure == FailureReason::none);
  CHECK(e.success_at_end());
  // Fall of 2 cm + the depth below the rim plus settling, then hold_steps at rest: well within 0.5 s.
  CHECK(e.info().step < 360);
  CHECK(e.info().step >= e.config().hold_steps);
  // Independently: the cup's centre of mass below the rim and within the basket's inner volume.
  const auto& cup = e.snapshot().objects[static_cast<std::size_t>(s.goal.object)];
  const auto& rc = sampler().library().get(s.objects[static_cast<std::size_t>(s.goal.container)].asset_id, "test").receptacles.at(0);
  const Eigen::Vector3d p = opening.inverse_act(cup.center_of_mass);
  CHECK(p.z() < 0);
  CHECK(p.z() > -rc.inner_depth);
  CHECK(!cup.touches_table);
  CHECK(cup.touches(s.goal.container));
}

TEST_CASE("bodies at rest sleep after the task world's time_to_sleep and still report their contacts", "[tasks][env]") {
  // COLL clean 3: a cup and a basket standing on the table (the goal not met), the arm held at
  // home for 250 control steps (0.35 s): they settle into the soft contact within a few steps.
  const SceneSpec s = sample(Task::coll, 3);
  const auto cup = static_cast<std::size_t>(s.goal.object);
  SECTION("0.1 s (the default): asleep, velocities zero, still touching the table") {
    TaskEnv& e = env();
    REQUIRE(e.config().time_to_sleep == 0.1);
    e.reset(s);
    hold_home(e, 250);
    REQUIRE_FALSE(e.done());
    CHECK_FALSE(e.world().rigid().is_awake(e.bodies().objects[cup]));
    const auto& o = e.snapshot().objects[cup];
    CHECK(o.linear_velocity.norm() == 0.0);
    CHECK(o.angular_velocity.norm() == 0.0);
    CHECK(o.touches_table);  // the sleeping pair's manifold is kept: the predicates see the contact
  }
  SECTION("0.5 s: still awake after 0.35 s") {
    manisoft::task::TaskEnvConfig c;
    c.time_to_sleep = 0.5;
    TaskEnv e(sampler().library(), c);
    e.reset(s);
    hold_home(e, 250);
    CHECK(e.world().rigid().is_awake(e.bodies().objects[cup]));
  }
  SECTION("a time_to_sleep of 0 is refused") {
    manisoft::task::TaskEnvConfig c;
    c.time_to_sleep = 0;
    CHECK_THROWS_WITH(TaskEnv(sampler().library(), c), Catch::Contains("time_to_sleep"));
  }
}

TEST_CASE("episodes end for the documented reasons: goal already met, object off the table, horizon", "[tasks][env]") {
  TaskEnv& e = env();
  SECTION("a goal that holds at reset is an invalid scene: done before the first step") {
    // ALN with the object standing at its goal pose.
    SceneSpec s = sample(Task::aln, 1);
    s.objects.at(static_cast<std::size_t>(s.goal.object)).pose = s.goal.goal_pose;
    e.reset(s);
    CHECK(e.done());
    CHECK(e.info().step == 0);
    CHECK_FALSE(e.info().success);
    CHECK(e.info().failure == FailureReason::scene_invalid);
    CHECK(e.info().terminated);
    CHECK_FALSE(e.info().truncated);
    TaskEnv::Array3 zero = TaskEnv::Array3::Zero(e.arm_model().rod.n_elements, 3);
    CHECK_THROWS_AS(e.step(zero, 0), manisoft::Error);
  }
  SECTION("COLL with the object already in its container, STK already stacked: invalid too") {
    // The cup at the basket's placement point (inside, below the rim): contacts are not known
    // before a step, so the position alone decides.
    SceneSpec coll = sample(Task::coll, 3);
    coll.objects.at(static_cast<std::size_t>(coll.goal.object)).pose.translation = container_placement(coll).translation;
    e.reset(coll);
    CHECK(e.info().failure == FailureReason::scene_invalid);
    CHECK(e.conditions().holds("inside"));
    // a scene file or a Python caller is told which conditions held already
    CHECK_THROWS_WITH(require_a_task(e, "coll.json"),
                      Catch::Matchers::StartsWith("coll.json: the goal already holds before any step (inside") &&
                          Catch::Matchers::EndsWith("): the scene is no task"));
    // The stack's items one above the other at the bottom item's place, 3 cm apart in height.
    SceneSpec stk = sample(Task::stk, 0);
    const Eigen::Vector3d bottom = stk.objects.at(static_cast<std::size_t>(stk.goal.items.front())).pose.translation;
    for (std::size_t k = 1; k < stk.goal.items.size(); ++k)
      stk.objects.at(static_cast<std::size_t>(stk.goal.items[k])).pose.translation = bottom + Eigen::Vector3d(0, 0, 0.03 * double(k));
    e.reset(stk);
    CHECK(e.info().failure == FailureReason::scene_invalid);
    // The sampled scenes themselves are tasks.
    e.reset(sample(Task::stk, 0));
    CHECK_FALSE(e.done());
    CHECK_NOTHROW(require_a_task(e, "stk.json"));
    CHECK_FALSE(e.conditions().all());
  }
  SECTION("a cup placed beyond the table's front edge falls off: object_off_table") {
    // table top x in [0, 0.8]: 5 cm beyond the edge, 1 cm above the top
    e.reset(coll_with_cup_at(Eigen::Vector3d(0.85, 0.0, 0.76)));
    hold_home(e);
    CHECK_FALSE(e.info().success);
    CHECK(e.info().failure == FailureReason::object_off_table);
    CHECK(e.info().terminated);
    CHECK(e.info().step < 400);  // a free fall below the top takes ~0.05 s
  }
  SECTION("nothing done: the horizon ends the episode with a timeout") {
    manisoft::task::TaskEnvConfig c;
    c.horizon = 40;
    TaskEnv shorter(sampler().library(), c);
    shorter.reset(sample(Task::coll, 3));
    hold_home(shorter);
    CHECK(shorter.info().step == 40);
    CHECK(shorter.info().failure == FailureReason::timeout);
    CHECK(shorter.info().truncated);
    CHECK_FALSE(shorter.info().terminated);
    // The explanation: the cup still stands on the table, away from the basket.
    CHECK(shorter.conditions().unmet() == "inside, touching_container, off_table");
  }
}

TEST_CASE("bad actions are refused naming the entry, and nothing changes", "[tasks][env]") {
  TaskEnv& e = env();
  e.reset(sample(Task::coll, 3));
  const Eigen::Vector3d before = e.world().soft().end_effector_frame().position;
  TaskEnv::Array3 torques = TaskEnv::Array3::Zero(e.arm_model().rod.n_elements, 3);
  torques(3, 1) = std::nan("");
  try {
    e.step(torques, 0);
    FAIL("a NaN torque was accepted");
  } catch (const manisoft::Error& err) {
    CHECK(std::strstr(err.what(), "(3, 1)") != nullptr);
  }
  torques(3, 1) = 0;
  CHECK_THROWS_AS(e.step(torques, 2), manisoft::Error);                                   // S must be 0 or 1
  CHECK_THROWS_AS(e.step(TaskEnv::Array3::Zero(5, 3), 0), manisoft::Error);              // wrong shape
  CHECK(e.info().step == 0);
  CHECK(e.world().soft().end_effector_frame().position == before);
  // A scene on another table is refused.
  SceneSpec other = sample(Task::coll, 3);
  other.table.half_x = 0.3;
  CHECK_THROWS_AS(e.reset(other), manisoft::Error);
}

TEST_CASE("no action sequence within the actuation limits diverges a task step", "[tasks][env][stability]") {
  // Constant at either bound, bang-bang, uniform random and random signs, with the gripper
  // toggling, in every task's first clean scene: the whipping arm may knock objects off the table
  // (the episode then restarts) but no step diverges.
  TaskEnv& e = env();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uniform(-1, 1);
  for (const Task task : all_tasks) {
    const SceneSpec s = sample(task, 0);
    for (int kind = 0; kind < 5; ++kind) {
      e.reset(s);
      const auto limits = e.world().settings().limits;
      TaskEnv::Array3 torques(e.arm_model().rod.n_elements, 3);
      int diverged = 0;
      for (int step = 0; step < 80; ++step) {
        if (e.done()) e.reset(s);
        for (int k = 0; k < torques.rows(); ++k)
          for (int c = 0; c < 3; ++c) {
            const double sign = kind == 0 ? 1 : kind == 1 ? -1 : kind == 2 ? ((step / 10) % 2 ? -1 : 1) : kind == 3 ? uniform(rng) : (uniform(rng) < 0 ? -1 : 1);
            torques(k, c) = sign * limits.limit(c);
          }
        diverged += e.step(torques, (step / 20) % 2).failure == FailureReason::diverged;
      }
      CAPTURE(to_string(task), kind);
      CHECK(diverged == 0);
      CHECK(e.world().rod().state().positions.allFinite());
    }
  }
}

TEST_CASE("a bad expert setting is refused naming the field", "[tasks][expert]") {
  TaskEnv& e = env();
  manisoft::task::ExpertConfig c;
  c.approach.tight_peak_speed = -0.5;
  CHECK_THROWS_WITH(Expert(e, c), Catch::Contains("ExpertConfig approach.tight_peak_speed = -0.5") && Catch::Contains("> 0"));
  c = {};
  c.checks.arm_clearance = std::nan("");
  CHECK_THROWS_WITH(Expert(e, c), Catch::Contains("ExpertConfig checks.arm_clearance = nan"));
  c = {};
  c.paths.cruise = 1.0;
  CHECK_THROWS_WITH(Expert(e, c), Catch::Contains("ExpertConfig paths.cruise = 1") && Catch::Contains("<= 0.95"));
  c = {};
  c.approach.max_retries = -1;
  CHECK_THROWS_WITH(Expert(e, c), Catch::Contains("ExpertConfig approach.max_retries = -1"));
  CHECK_NOTHROW(Expert(e, {}));
}

TEST_CASE("the expert configuration reads from JSON by group and refuses what it does not have", "[tasks][expert]") {
  using manisoft::task::ExpertConfig;
  using manisoft::task::expert_config_from_json;
  using nlohmann::json;
  // a file names only what it changes; the rest keeps its default
  const ExpertConfig partial = expert_config_from_json(json::parse(R"({"carry": {"peak_speed": 1.2}, "checks": {"objects": false}})"), "a.json");
  CHECK(partial.carry.peak_speed == 1.2);
  CHECK_FALSE(partial.checks.objects);
  CHECK(partial.paths.peak_speed == 1.5);
  CHECK(partial.settle.max_steps == 200);
  // round trip: every setting written, in eight groups, and read back to the same values
  ExpertConfig c;
  c.lower.slow_distance = 0.04;
  c.settle.max_steps = 150;
  c.paths.ramp_fallback = false;
  const json written = manisoft::task::to_json(c);
  CHECK(written.size() == 8);
  CHECK(written.at("lower").at("slow_distance") == 0.04);
  CHECK(written.at("approach").size() == 7);
  const ExpertConfig back = expert_config_from_json(written, "b.json");
  CHECK(back.lower.slow_distance == 0.04);
  CHECK(back.settle.max_steps == 150);
  CHECK_FALSE(back.paths.ramp_fallback);
  CHECK(back.carry.grip_share == 0.45);
  CHECK(manisoft::task::to_json(back) == written);
  // refused, naming the file and the key
  CHECK_THROWS_WITH(expert_config_from_json(json::parse(R"({"carry": {"speed": 1}})"), "c.json"),
                    Catch::Contains("c.json: carry.speed is not a setting"));
  CHECK_THROWS_WITH(expert_config_from_json(json::parse(R"({"grasp": {"distance": 1}})"), "c.json"),
                    Catch::Contains("c.json: grasp.distance is not a setting"));
  CHECK_THROWS_WITH(expert_config_from_json(json::parse(R"({"carry": {"peak_speed": -1}})"), "d.json"),
                    Catch::Contains("d.json: ExpertConfig carry.peak_speed = -1") && Catch::Contains("> 0"));
  CHECK_THROWS_WITH(expert_config_from_json(json::parse(R"({"paths": {"cruise": 1.5}})"), "d.json"),
                    Catch::Contains("d.json: ExpertConfig paths.cruise = 1.5") && Catch::Contains("<= 0.95"));
  CHECK_THROWS_WITH(expert_config_from_json(json::parse(R"({"settle": {"max_steps": 1.5}})"), "e.json"),
                    Catch::Contains("e.json: settle.max_steps = 1.5") && Catch::Contains("an integer"));
  CHECK_THROWS_WITH(expert_config_from_json(json::parse(R"({"settle": {"max_steps": 3000000000}})"), "e.json"),
                    Catch::Contains("e.json: settle.max_steps = 3000000000") && Catch::Contains("int"));
  CHECK_THROWS_WITH(expert_config_from_json(json::parse(R"({"checks": {"objects": 0}})"), "e.json"),
                    Catch::Contains("e.json: checks.objects = 0") && Catch::Contains("true or false"));
  CHECK_THROWS_WITH(expert_config_from_json(json::parse(R"({"carry": 1.2})"), "e.json"), Catch::Contains("e.json: carry must be an object"));
  // from a file: a key given twice and a syntax error name the file
  const auto dir = manisoft::test::scratch_dir("expert_config_json");
  const std::string twice = (dir / "twice.json").string(), broken = (dir / "broken.json").string();
  std::ofstream(twice) << R"({"carry": {"peak_speed": 1.2, "peak_speed": 1.0}})";
  std::ofstream(broken) << R"({"carry": {"peak_speed": 1.2)";
  CHECK_THROWS_WITH(manisoft::task::load_expert_config(twice), Catch::Contains(twice) && Catch::Contains("carry.peak_speed: duplicate key"));
  CHECK_THROWS_WITH(manisoft::task::load_expert_config(broken), Catch::Contains(broken) && Catch::Contains("not valid JSON"));
}

TEST_CASE("an expert episode is deterministic: two runs give bit-identical states", "[tasks][expert]") {
  const SceneSpec s = sample(Task::aln, 1);
  auto run = [&](int steps) {
    TaskEnv& e = env();
    Expert expert(e);
    run_expert(e, expert, s, steps);
    return std::make_pair(e.world().rod().state().positions, e.snapshot().objects[0].pose.translation);
  };
  const auto a = run(400), b = run(400);
  CHECK((a.first.array() == b.first.array()).all());
  CHECK((a.second.array() == b.second.array()).all());
}

TEST_CASE("the expert does not plan the arm through an obstacle in its way", "[tasks][expert]") {
  // ALN clean 6: the bottle at (0.29, 0.33), 0.4 m from the home pose; a vase (12 cm wide, 21 cm
  // tall) halfway between them, 0.2 m from each, under the arm's way to the bottle. With the
  // check the expert refuses every plan (no detour around it is planned) and the arm never
  // touches the vase; without it, the arm runs into it.
  SceneSpec s = sample(Task::aln, 6);
  const Eigen::Vector3d object = s.objects.at(static_cast<std::size_t>(s.goal.object)).pose.translation;
  PlacedAsset vase;
  vase.asset_id = "vase/00";
  vase.pose.translation = Eigen::Vector3d(0.5 + 0.5 * (object.x() - 0.5), 0.5 * object.y(), s.table.top_center.z());
  s.obstacles.push_back(vase);
  for (const bool check : {true, false}) {
    CAPTURE(check);
    manisoft::task::ExpertConfig config;
    config.checks.objects = check;
    TaskEnv& e = env();
    Expert expert(e, config);
    run_expert(e, expert, s);
    const std::string why(expert.failure().value_or(""));
    CAPTURE(why, manisoft::task::to_string(e.info().failure));
    CHECK_FALSE(e.info().success);
    if (check) {
      CHECK(why.find("the arm would hit an object or obstacle") != std::string::npos);
      CHECK(e.info().failure == FailureReason::timeout);
    } else {
      CHECK(e.info().failure == FailureReason::arm_hit_obstacle);
    }
  }
}

TEST_CASE("the expert solves fixed clean scenes within the horizon", "[tasks][expert]") {
  // Scenes the expert solves today (the README's table gives its rate over many scenes).
  const std::pair<Task, std::uint64_t> scenes[] = {{Task::coll, 0}, {Task::aln, 1}, {Task::aln, 9}, {Task::arr, 13}};
  int solved = 0;
  for (const auto& [t, index] : scenes) {
    CAPTURE(to_string(t), index);
    TaskEnv& e = env();
    Expert expert(e);
    run_expert(e, expert, sample(t, index));
    CAPTURE(expert.failure().value_or(""), manisoft::task::to_string(e.info().failure));
    if (e.info().success) {
      ++solved;
      CHECK(e.info().step <= e.config().horizon);
      // it let go before success (and is moving away or holding still)
      CHECK((expert.phase() == manisoft::task::ExpertPhase::retract || expert.phase() == manisoft::task::ExpertPhase::idle));
    }
  }
  CHECK(solved == 4);  // every one of them
}

TEST_CASE("OVR: the expert carries the object over the tall obstacle between it and the marker", "[tasks][expert]") {
  // Fixed clean OVR scenes (an object, a marker, an obstacle 0.15-0.25 m tall halfway between
  // them): the held object's bottom passes higher than the obstacle's top, and the episode
  // succeeds within the horizon without the arm touching the obstacle.
  for (const std::uint64_t index : {3u, 5u}) {
    CAPTURE(index);
    const SceneSpec s = sample(Task::ovr, index);
    const auto& wall = s.obstacles.at(static_cast<std::size_t>(s.goal.obstacle));
    const auto& wa = sampler().library().get(wall.asset_id, "test");
    const double wall_top = wall.pose.act(wa.bounding_center).z() + wa.bounding_half_extents.z();
    REQUIRE(wall_top - s.table.top_center.z() >= 0.15);
    TaskEnv& e = env();
    Expert expert(e);
    double highest = 0;  // m: the held object's bottom (its asset origin), highest while held
    run_expert(e, expert, s, 100000, [&](manisoft::task::ExpertPhase) {
      const auto& o = e.snapshot().objects[static_cast<std::size_t>(s.goal.object)];
      if (o.held) highest = std::max(highest, o.pose.translation.z());
    });
    CAPTURE(expert.failure().value_or(""), manisoft::task::to_string(e.info().failure));
    CHECK(e.info().success);
    CHECK(e.info().step <= e.config().horizon);
    CHECK(highest > wall_top);
  }
}

TEST_CASE("the open fingers come down onto a tall object from above and do not knock it over", "[tasks][expert]") {
  // COLL clean 3: a cup (9 cm tall) 0.45 m from the home pose, whose annotated approach pose
  // leaves the open fingertips 5 mm below its rim. A level approach swept the fingers into it and
  // tipped it by 1 rad before the grasp. The expert now comes in above it (its via point raised
  // until the fingertips pass 2 cm over the rim) and descends straight onto it: upright, unmoved
  // and held.
  const SceneSpec s = sample(Task::coll, 3);
  const std::size_t cup = static_cast<std::size_t>(s.goal.object);
  REQUIRE(s.objects.at(cup).asset_id.rfind("cup/", 0) == 0);
  TaskEnv& e = env();
  Expert expert(e);
  e.reset(s);
  const auto start = e.snapshot().objects[cup].pose;
  double tilt = 0, shift = 0;
  bool held = false;
  run_expert(e, expert, s, 100000, [&](manisoft::task::ExpertPhase phase) {
    const auto now = e.snapshot().objects[cup].pose;
    if (phase == manisoft::task::ExpertPhase::approach || phase == manisoft::task::ExpertPhase::descend) {
      tilt = std::max(tilt, std::acos(std::clamp(now.rotation.col(2).dot(start.rotation.col(2)), -1.0, 1.0)));
      shift = std::max(shift, (now.translation - start.translation).norm());
    }
    if (phase == manisoft::task::ExpertPhase::carry) held = true;
  });
  CAPTURE(expert.failure().value_or(""), manisoft::task::to_string(e.info().failure));
  CHECK(tilt < 0.02);
  CHECK(shift < 0.003);
  CHECK(held);
}

TEST_CASE("the expert descends to a tight grasp slowly and stacks two plates", "[tasks][expert]") {
  // STK clean 2: two plates, whose grasps leave less than approach.tight_clearance between each open finger
  // and the rim. A fast descent sways the arm sideways by about as much and tips the plate.
  const SceneSpec s = sample(Task::stk, 2);
  TaskEnv& e = env();
  const manisoft::task::ExpertConfig config;
  Expert expert(e, config);
  for (const auto& o : s.objects) {
    const auto& asset = sampler().library().get(o.asset_id, "test");
    CAPTURE(o.asset_id);
    REQUIRE(asset.grasps.size() > 0);
    for (const auto& g : asset.grasps) CHECK(0.5 * (e.gripper_parameters().open_width - g.width) < config.approach.tight_clearance);
  }
  double descend_peak = 0;  // m/s, the end-effector's downward speed over the descend phase, one control step apart
  int descend_steps = 0;
  Eigen::Vector3d last = Eigen::Vector3d::Zero();  // set at every step; the first step is an approach
  run_expert(e, expert, s, 100000, [&](manisoft::task::ExpertPhase phase) {
    const Eigen::Vector3d now = e.world().soft().end_effector_frame().position;
    if (phase == manisoft::task::ExpertPhase::descend) {
      descend_peak = std::max(descend_peak, (last.z() - now.z()) / e.control_dt());
      ++descend_steps;
    }
    last = now;
  });
  CAPTURE(expert.failure().value_or(""), manisoft::task::to_string(e.info().failure), descend_steps);
  CHECK(e.info().success);
  REQUIRE(descend_steps > 0);
  // a plate is grasped from above; the descent's planned peak is approach.tight_peak_speed (0.6 m/s;
  // paths.peak_speed, 1.5 m/s, for a loose grasp): tracking may overshoot the plan a little, not
  // by a factor of 2.5 (the arm still sways sideways from the approach as the descent begins)
  CHECK(descend_peak < 1.5 * config.approach.tight_peak_speed);
}

TEST_CASE("a stack of three fits the horizon: two moves with the task world's executor", "[tasks][expert]") {
  // STK clean 97: three bowls, two moves of about 600 control steps each. With the reach
  // environment's node velocity feedback (kd 35 /s) the arm swayed for about 100 control steps
  // after every path and the settling waits ran stacks of three out of the horizon; the task
  // world's executor (TaskEnvConfig::task_executor_settings, kd 70 /s) damps the sway.
  const SceneSpec s = sample(Task::stk, 97);
  REQUIRE(s.objects.size() == 3);
  TaskEnv& e = env();
  CHECK(e.config().executor.damping_gain == 2 * manisoft::control::ModelExecutorSettings<double>{}.damping_gain);
  Expert expert(e);
  run_expert(e, expert, s);
  CAPTURE(expert.failure().value_or(""), manisoft::task::to_string(e.info().failure), e.info().step);
  CHECK(expert.moves() == 2);
  CHECK(e.info().success);
  CHECK(e.info().step <= e.config().horizon);
}

TEST_CASE("a held line's acceleration stays within the grip: a tall bottle is not dropped at the lift", "[tasks][expert]") {
  // ARR clean 44: the bottle is grasped high; the carry starts with a 6 cm lift. Timed by the
  // carry's speed alone (carry.grip_share 0) the lift's 60 control steps accelerated it at about
  // 10 g and the weld's force passed the grip's max_hold_force (40 N): it slipped out (before the
  // fingers moved; it now holds at a different grasp). Bounded to carry.grip_share x
  // max_hold_force / mass, the lift takes longer: the weld's force over the carry is lower than
  // unbounded, within the grip, and the bottle stays held and ends in the row, at rest (it rocks
  // on its base for about 230 control steps after the release, so success comes at the horizon
  // or just after it: the predicate is checked as it holds at the end).
  const SceneSpec s = sample(Task::arr, 44);
  TaskEnv& e = env();
  struct Carry {
    bool slipped = false;  // the gripper, closed (S = 1) in the carry, no longer holds anything
    double max_force = 0;  // N: the weld's elastic force
  };
  auto carry = [&](const manisoft::task::ExpertConfig& config) {
    Expert expert(e, config);
    Carry c;
    run_expert(e, expert, s, 100000, [&](manisoft::task::ExpertPhase phase) {
      if (phase != manisoft::task::ExpertPhase::carry) return;
      if (!e.world().gripper().held()) c.slipped = true;
      c.max_force = std::max(c.max_force, e.world().gripper().grip_force());
    });
    return c;
  };
  manisoft::task::ExpertConfig unbounded;
  unbounded.carry.grip_share = 0;
  const Carry fast = carry(unbounded);
  const Carry bounded = carry({});
  CAPTURE(fast.max_force, bounded.max_force, manisoft::task::to_string(e.info().failure));
  CHECK(bounded.max_force < fast.max_force);
  CHECK(bounded.max_force < e.world().gripper().parameters().max_hold_force);
  CHECK_FALSE(bounded.slipped);
  CHECK(e.success_at_end());
}

TEST_CASE("the arm leaves a released tall object only once the opening fingers clear it", "[tasks][expert]") {
  // Fingers still on the object as the arm moves off drag it along; with a noisy arm a tall one
  // tips over (ALN with torque noise: bottles and candle sticks left lying). After S = 0 the arm
  // holds still over a tall object until the gap exceeds the grasp's by release.clearance on each
  // side: measured against the gap the fingers stopped at on the object in the carry, less one
  // step's opening (the fingers open at open_width / stroke_time). From a low object (a shoe)
  // it leaves at once.
  using manisoft::task::ExpertPhase;
  struct Release {
    double held_gap = -1, gap_at_retract = -1, rise_while_open = 0;
    int open_steps = 0;
    bool success = false;
    std::string object;  // the asset moved
  };
  TaskEnv& e = env();
  auto release = [&](std::uint64_t index) {
    const SceneSpec s = sample(Task::aln, index);
    Expert expert(e);
    Release r;
    r.object = s.objects.at(static_cast<std::size_t>(s.goal.object)).asset_id;
    double z_at_open = 0;
    ExpertPhase last = ExpertPhase::approach;
    run_expert(e, expert, s, 100000, [&](ExpertPhase phase) {
      const double gap = e.world().gripper().finger_width();
      const double z = e.world().soft().end_effector_frame().position.z();
      if (phase == ExpertPhase::carry) r.held_gap = gap;
      if (phase == ExpertPhase::open) {
        if (last != ExpertPhase::open) z_at_open = z;
        r.rise_while_open = std::max(r.rise_while_open, z - z_at_open);
        ++r.open_steps;
      }
      if (phase == ExpertPhase::retract && last == ExpertPhase::open) r.gap_at_retract = gap;
      last = phase;
    });
    r.success = e.info().success;
    return r;
  };
  const Release bottle = release(2);  // ALN clean 2: a bottle (tall)
  REQUIRE(bottle.object.rfind("bottle/", 0) == 0);
  const double clearance = manisoft::task::ExpertConfig{}.release.clearance;
  const auto gripper = e.world().gripper().parameters();  // the world exists once reset
  const double step_opening = gripper.open_width / gripper.stroke_time * e.control_dt();
  CAPTURE(bottle.held_gap, bottle.gap_at_retract, bottle.open_steps, bottle.rise_while_open, step_opening);
  REQUIRE(bottle.held_gap > 0);
  CHECK(bottle.gap_at_retract >= std::min(bottle.held_gap + 2 * clearance, gripper.open_width) - step_opening);
  CHECK(bottle.open_steps >= static_cast<int>((std::min(bottle.held_gap + 2 * clearance, gripper.open_width) - bottle.held_gap) / step_opening) - 1);
  CHECK(bottle.rise_while_open < 0.005);
  CHECK(bottle.success);
  const Release shoe = release(1);  // ALN clean 1: a shoe (low)
  REQUIRE(shoe.object.rfind("shoe/", 0) == 0);
  CAPTURE(shoe.held_gap, shoe.gap_at_retract, shoe.open_steps);
  CHECK(shoe.open_steps == 1);
  CHECK(shoe.success);
}

TEST_CASE("the carry lifts the held object and the gripper over the container's rim", "[tasks][expert]") {
  // COLL clean 22: the pill bottle stands 25 cm from the basket's centre. A carry straight from
  // the grasp to above the basket rises through the rim: unchecked, the held bottle pushes the
  // basket 15 cm aside; the expert checks the held object and the gripper along the carry.
  const SceneSpec s = sample(Task::coll, 22);
  TaskEnv& e = env();
  auto container_travel = [&](const manisoft::task::ExpertConfig& config) {
    Expert expert(e, config);
    e.reset(s);
    const Eigen::Vector3d start = e.snapshot().objects[static_cast<std::size_t>(s.goal.container)].pose.translation;
    double travel = 0;
    run_expert(e, expert, s, 100000, [&](manisoft::task::ExpertPhase) {
      travel = std::max(travel, (e.snapshot().objects[static_cast<std::size_t>(s.goal.container)].pose.translation - start).norm());
    });
    return travel;
  };
  // At the carry speed this scene was found with (1.2 m/s; at the default 1.5 the unchecked carry
  // only nudges the basket 4 mm).
  manisoft::task::ExpertConfig checked;
  checked.carry.peak_speed = checked.carry.node_speed = 1.2;
  manisoft::task::ExpertConfig unchecked = checked;
  unchecked.checks.objects = false;
  CHECK(container_travel(unchecked) > 0.05);
  const double travel = container_travel(checked);
  CAPTURE(manisoft::task::to_string(e.info().failure));
  CHECK(e.info().success);
  CHECK(travel < 0.005);
}

TEST_CASE("a descent that ends short of its grasp backs off and re-tries with another grasp", "[tasks][expert]") {
  // COLL clean 3 (a cup and a basket) with approach.grasp_error so small that every descent counts as
  // blocked: the first backs off along its approach with the gripper open and the move is planned
  // again without that grasp (the cup's next yaw); the second, with no re-try left, closes.
  const SceneSpec s = sample(Task::coll, 3);
  const std::size_t cup = static_cast<std::size_t>(s.goal.object);
  TaskEnv& e = env();
  manisoft::task::ExpertConfig config;
  config.approach.grasp_error = 1e-5;
  config.approach.max_retries = 1;
  Expert expert(e, config);
  std::vector<manisoft::task::ExpertPhase> phases;
  std::vector<Eigen::Matrix3d> descent_ends;  // the cup's frame in the gripper's as each descent ends
  bool held_while_backing_off = false;
  auto previous = manisoft::task::ExpertPhase::idle;
  run_expert(e, expert, s, 100000, [&](manisoft::task::ExpertPhase phase) {
    if (phase != previous) phases.push_back(phase);
    if (previous == manisoft::task::ExpertPhase::descend && phase != previous) {
      const auto& r = e.world().rigid();
      const Eigen::Matrix3d gripper = r.orientation(e.world().gripper_body()).toRotationMatrix();
      descent_ends.push_back(gripper.transpose() * e.snapshot().objects[cup].pose.rotation);
    }
    if (phase == manisoft::task::ExpertPhase::retract && expert.move() == 0 && e.world().gripper().held()) held_while_backing_off = true;
    previous = phase;
  });
  using P = manisoft::task::ExpertPhase;
  const std::vector<P> expected = {P::approach, P::descend, P::retract, P::approach, P::descend, P::close, P::carry};
  REQUIRE(phases.size() >= expected.size());
  CHECK(std::equal(expected.begin(), expected.end(), phases.begin()));
  CHECK_FALSE(held_while_backing_off);
  REQUIRE(descent_ends.size() >= 2);
  // the cup is round: the re-try's grasp is the same annotation turned about its axis (at least
  // the 0.2 rad the exclusion compares)
  CHECK(Eigen::AngleAxisd(descent_ends[0] * descent_ends[1].transpose()).angle() > 0.2);
  CAPTURE(expert.failure().value_or(""), manisoft::task::to_string(e.info().failure));
  CHECK(e.info().success);
}

}  // namespace test_task_env
