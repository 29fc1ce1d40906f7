// Recording a task episode (include/manisoft/dataset/expert_recording.hpp) and replaying it: the
// stored states match a replay from the scene JSON and the actions bit for bit, also after a
// round trip through the episode file; a changed action is caught at the next step; the first
// state is the scene as sampled (rod clamped at the mount, objects where the scene put them); the
// recorded end-effector targets, read back from the file (float32) and sent at 20 Hz, drive the
// end-effector track to the expert's outcome.
#include <catch2/catch.hpp>

#include <filesystem>

#include "manisoft/dataset/episode_file.hpp"
#include "manisoft/dataset/expert_recording.hpp"
#include "manisoft/scene/scene_sampler.hpp"
#include "manisoft/task/ee_track.hpp"
#include "manisoft/task/expert.hpp"
#include "../support/scratch_dir.hpp"

using namespace manisoft;

TEST_CASE("a recorded expert episode replays bit for bit, from memory and from its file", "[dataset][tasks]") {
  scene::SceneSampler sampler;
  scene::SampleRequest q;
  q.task = scene::Task::arr;
  q.index = 1;  // ARR clean train scene 1 (any outcome would do)
  const scene::SceneSpec spec = sampler.sample(q);
  task::TaskEnv env(sampler.library());
  task::Expert expert(env);
  env.reset(spec);
  expert.reset();
  dataset::EpisodeRecorder recorder(env);
  task::TaskEnv::Array3 torques;
  int s = 0;
  while (!env.done()) {
    expert.act(torques, s);
    recorder.step(torques, s, expert.target());
    env.step(torques, s);
  }
  const dataset::Episode e = recorder.finish(3, 0, 0);
  const int n = env.arm_model().rod.n_elements;
  const int objects = static_cast<int>(spec.objects.size());
  REQUIRE(e.steps() == env.info().step);
  REQUIRE(e.actions.cols() == 3 * n + 1);
  REQUIRE(e.states.cols() == 3 * (n + 1) + 7 * objects + 2);
  // step 0: node 0 at the mount, objects at the scene's poses, gripper open
  CHECK((e.states.row(0).head(3).transpose() - spec.arm_mount.base_position).norm() < 1e-9);
  for (int i = 0; i < objects; ++i)
    CHECK((e.states.row(0).segment(3 * (n + 1) + 7 * i, 3).transpose() - spec.objects[static_cast<std::size_t>(i)].pose.translation).norm() < 1e-9);
  CHECK(e.states(0, e.states.cols() - 1) == 0.0);
  // obs/rod_directors: every element's frame orthonormal, its d3 along the centreline (the shear
  // of the arm at rest is small)
  const auto& directors = e.observations.at("rod_directors");
  REQUIRE(directors.cols() == 9 * n);
  for (const long r : {0L, e.steps() / 2, e.steps() - 1}) {
    for (int k = 0; k < n; ++k) {
      Eigen::Matrix3d Q;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) Q(i, j) = directors(r, 9 * k + 3 * i + j);
      CHECK((Q * Q.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-9);
      const Eigen::Vector3d tangent = (e.states.row(r).segment<3>(3 * (k + 1)) - e.states.row(r).segment<3>(3 * k)).transpose().normalized();
      CHECK(Q.row(2).dot(tangent) > 0.999);
    }
  }
  CHECK(e.dones.back() == 1);
  CHECK(e.rewards.sum() == (env.info().success ? 1.0 : 0.0));
  CHECK(e.numbers.at("steps") == static_cast<double>(e.steps()));

  CHECK(dataset::replay_mismatch(env, e) == -1);

  const auto path = manisoft::test::scratch_dir("manisoft_test_recording") / "episode.hdf5";
  dataset::write_episode(path, e);
  const dataset::Episode back = dataset::read_episode(path, 3);
  std::filesystem::remove(path);
  CHECK(dataset::replay_mismatch(env, back) == -1);

  dataset::Episode changed = back;
  changed.actions(100, 3 * 5) += 1.0;  // element 5, d1: 1 N m more at step 100
  CHECK(dataset::replay_mismatch(env, changed) == 101);

  // obs/ee_target: the expert's target at each step (its S the action's), obs/ee_waypoint counts
  // its changes; sent to the end-effector track every action_repeat steps they reach the same outcome
  const auto& target = back.observations.at("ee_target");
  const auto& waypoint = back.observations.at("ee_waypoint");
  REQUIRE(target.cols() == 7);
  CHECK(waypoint(0, 0) == 0.0);
  int changes = 0;
  for (long r = 0; r < back.steps(); ++r) {
    CHECK(target(r, 6) == back.actions(r, 3 * n));
    if (r > 0 && target.row(r).head(6) != target.row(r - 1).head(6)) ++changes;  // the pose, not S
  }
  CHECK(waypoint(back.steps() - 1, 0) == changes);
  CHECK(changes >= 4);
  task::EndEffectorTrack track(env);
  env.reset(spec);
  track.reset();
  const int repeat = track.config().action_repeat;
  for (long k = 0; !env.done();) {
    const task::EeAction a = target.row(std::min(k, back.steps() - 1)).transpose();
    track.command(task::ee_target_of(a, env.home_pose().rotation));
    for (int r = 0; r < repeat && !env.done(); ++r, ++k) {
      track.act(torques);
      env.step(torques, static_cast<int>(a(6)));
    }
  }
  CHECK(env.info().success == (e.rewards.sum() == 1.0));
}
