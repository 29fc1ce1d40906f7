// The end-effector track (include/manisoft/task/ee_track.hpp): fed the expert's own targets and
// gripper states, recorded at every control step of an expert episode and sampled every
// action_repeat steps, it solves the scenes the expert solves; a bad target is refused with an
// error and an unreachable one is refused with the arm's target kept; a target within min_change
// of the current one starts nothing.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "manisoft/scene/scene_sampler.hpp"
#include "manisoft/task/ee_track.hpp"
#include "manisoft/task/expert.hpp"
#include "manisoft/task/task_env.hpp"

namespace test_ee_track {  // per-file namespace: the group's tests build as one unity translation unit

using Pose = manisoft::math::Pose<double>;
using manisoft::task::EeCommand;
using manisoft::task::EndEffectorTrack;
using manisoft::task::Expert;
using manisoft::task::TaskEnv;
using namespace manisoft::scene;

namespace {

SceneSampler& sampler() {
  static SceneSampler s;
  return s;
}

SceneSpec sample(Task t, std::uint64_t index) {
  SampleRequest q;
  q.task = t;
  q.setting = Setting::clean;
  q.split = Split::eval;
  q.index = index;
  return sampler().sample(q);
}

}  // namespace

TEST_CASE("the end-effector track fed the expert's recorded targets at 20 Hz solves the scenes the expert solves", "[tasks][ee_track]") {
  TaskEnv env(sampler().library());
  Expert expert(env);
  EndEffectorTrack track(env);
  const int repeat = track.config().action_repeat;
  REQUIRE(repeat * env.control_dt() == Approx(1.0 / 20).epsilon(0.01));
  TaskEnv::Array3 torques;
  for (const auto& [t, index] : {std::pair{Task::coll, 0}, std::pair{Task::aln, 1}, std::pair{Task::stk, 2}}) {
    CAPTURE(to_string(t), index);
    const SceneSpec spec = sample(t, std::uint64_t(index));
    env.reset(spec);
    expert.reset();
    std::vector<Pose> targets;
    std::vector<int> states;
    while (!env.done()) {
      int s = 0;
      expert.act(torques, s);
      targets.push_back(expert.target());
      states.push_back(s);
      env.step(torques, s);
    }
    REQUIRE(env.info().success);
    const long expert_steps = env.info().step;

    env.reset(spec);
    track.reset();
    CHECK((track.target().translation - env.home_pose().translation).norm() == 0.0);
    int lines = 0;
    for (std::size_t k = 0; !env.done();) {
      const std::size_t j = std::min(k, targets.size() - 1);
      const EeCommand c = track.command(targets[j]);
      CHECK(c != EeCommand::refused);
      lines += c == EeCommand::line;
      for (int r = 0; r < repeat && !env.done(); ++r, ++k) {
        track.act(torques);
        env.step(torques, states[j]);
      }
    }
    CAPTURE(manisoft::task::to_string(env.info().failure), expert_steps, env.info().step, lines);
    CHECK(env.info().success);
    CHECK(lines >= 4);  // at least approach, descend, carry and retract
  }
}

TEST_CASE("the end-effector track refuses a bad or unreachable target and keeps the one it has", "[tasks][ee_track]") {
  TaskEnv env(sampler().library());
  EndEffectorTrack track(env);
  env.reset(sample(Task::aln, 1));
  track.reset();
  const Pose home = track.target();

  Pose nan = home;
  nan.translation.x() = std::nan("");
  CHECK_THROWS_WITH(track.command(nan), Catch::Contains("not finite"));
  Pose skew = home;
  skew.rotation(0, 1) += 0.1;
  CHECK_THROWS_WITH(track.command(skew), Catch::Contains("not a rotation"));
  Pose mirrored = home;
  mirrored.rotation.col(2) *= -1;
  CHECK_THROWS_WITH(track.command(mirrored), Catch::Contains("not a rotation"));

  Pose near = home;
  near.translation.z() += 0.5 * track.config().min_change;
  CHECK(track.command(near) == EeCommand::kept);

  Pose far = home;  // 3 m from a 1 m arm's base
  far.translation = Eigen::Vector3d(2.5, 0.0, 0.9);
  CHECK(track.command(far) == EeCommand::refused);
  CHECK((track.target().translation - home.translation).norm() == 0.0);

  Pose aside = home;  // 10 cm aside and 5 cm up, clear of the scene: a straight line
  aside.translation += Eigen::Vector3d(-0.05, 0.10, 0.05);
  CHECK(track.command(aside) == EeCommand::line);
  TaskEnv::Array3 torques;
  for (int k = 0; k < 400 && !env.done(); ++k) {
    track.act(torques);
    env.step(torques, 0);
  }
  const auto ee = env.world().soft().end_effector_frame();
  CHECK((ee.position - aside.translation).norm() < 0.01);

  manisoft::task::EeTrackConfig bad;
  bad.action_repeat = 0;
  CHECK_THROWS_WITH(EndEffectorTrack(env, bad), Catch::Contains("action_repeat = 0"));
  bad = {};
  bad.paths.peak_speed = -1;
  CHECK_THROWS_WITH(EndEffectorTrack(env, bad), Catch::Contains("peak_speed"));
}

}  // namespace test_ee_track
