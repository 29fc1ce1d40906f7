// A dataset written by the generate_dataset program (examples/benchmark/generate_dataset.cpp) replays
// bit for bit from its files: the program writes two ALN episodes (one clean, one randomized), the
// test opens the index and the episode files it links and replays each episode from its stored
// scene and actions (dataset::replay_mismatch); one changed action is reported at the step after it.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "../support/command_line.hpp"
#include "../support/scratch_dir.hpp"
#include "manisoft/dataset/dataset_index.hpp"
#include "manisoft/dataset/expert_recording.hpp"
#include "manisoft/scene/scene_sampler.hpp"

namespace test_generated_replay {  // per-file namespace: the group's tests build as one unity translation unit

using namespace manisoft;

TEST_CASE("a dataset written by generate_dataset replays bit for bit from its files", "[dataset][tasks]") {
  const auto dir = manisoft::test::scratch_dir("manisoft_generated_replay");
  const std::string out = (dir / "data").string(), log = (dir / "log.txt").string();
  const int code = manisoft::test::run_command(MANISOFT_GENERATE_DATASET, "--tasks ALN --clean 1 --randomized 1 --seed 4 --jobs 1 --out " + out, log);
  INFO(manisoft::test::slurp(log));
  REQUIRE(code == 0);
  const dataset::h5::File index = dataset::h5::File::open(dataset::index_file(out).string());
  const std::vector<std::string> demos = index.children("/data");
  REQUIRE(demos == std::vector<std::string>{"demo_0", "demo_1"});

  scene::SceneSampler sampler;
  task::TaskEnv env(sampler.library());
  for (long k = 0; k < 2; ++k) {
    CAPTURE(k);
    const dataset::Episode e = dataset::read_episode(dataset::episode_file(out, k), k);
    CHECK(e.text.at("task") == "ALN");
    CHECK(e.text.at("setting") == (k == 0 ? "clean" : "randomized"));
    REQUIRE(e.steps() > 100);
    CHECK(dataset::replay_mismatch(env, e) == -1);
    CHECK(env.info().success);  // generate_dataset keeps successful episodes only
    CHECK(env.info().step == e.steps());

    dataset::Episode changed = e;
    const long step = e.steps() / 2;
    double& torque = changed.actions(step, 3 * 4 + 1);  // element 4, d2: 0.5 N m towards zero (within the limits)
    torque += torque > 0 ? -0.5 : 0.5;
    CHECK(dataset::replay_mismatch(env, changed) == step + 1);
  }
}

}  // namespace test_generated_replay
