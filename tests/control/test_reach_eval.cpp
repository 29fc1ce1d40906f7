// reach_eval, run as a user scripts it: an MLP policy file drives the arm through
// `--executor mlp --weights FILE` to the pose its outputs hold, the model executor reaches
// targets through the B-spline action space, and bad flags or files are refused.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "../support/command_line.hpp"
#include "../support/scratch_dir.hpp"
#include "manisoft/rod/inverse_statics.hpp"
#include "manisoft/control/mlp_executor.hpp"
#include "manisoft/env/reach_env.hpp"

namespace {

using manisoft::test::read_csv;
using manisoft::test::slurp;

const std::string scratch = manisoft::test::scratch_dir("manisoft_reach_eval_test").string();

int run(const std::string& arguments) {
  // test_world does not depend on the reach_eval target (the build then starts it early)
  INFO("the reach_eval program is missing: build the reach_eval target (" MANISOFT_REACH_EVAL ")");
  REQUIRE(std::filesystem::exists(MANISOFT_REACH_EVAL));
  std::filesystem::create_directories(scratch);
  return manisoft::test::run_command(MANISOFT_REACH_EVAL, arguments, scratch + "/log.txt");
}

std::string log_text() { return slurp(scratch + "/log.txt"); }

// CSV columns of reach_eval (see examples/reach_eval.cpp).
constexpr int success_column = 7, position_error_column = 9, rotation_error_column = 10, node_speed_column = 19, path_ratio_column = 20;

}  // namespace

TEST_CASE("an MLP policy file drives the arm to the equilibrium its outputs hold", "[executor][mlp][reach_eval]") {
  // A policy "trained elsewhere" whose outputs are known: zero weights and, as biases, the
  // inverse statics feed-forward torques of the run's only target (reach_eval's target 0 of seed
  // S is the environment's seed S * 1000003). Open loop through the MLP executor the arm settles
  // where these torques hold it: at the target, up to what the executor's model leaves out (the
  // gripper's mass sits below the palm, not on the tip node; the spring sags m g / kF = 0.1 mm).
  // Open loop needs damping: with PyElastica's light analytical damping the follower
  // feed-forward alone flutters (measured 0.06-1.4 m off after 6000 control steps), as the model
  // executor's header says; uniform damping 5 /s settles within the horizon.
  manisoft::env::ReachEnvConfig config;
  config.target_set = manisoft::env::TargetSet::equilibria;
  manisoft::env::ReachEnv<manisoft::rod::damping::UniformExp> env(config, manisoft::rod::damping::UniformExp<double>(5));
  const auto& observation = env.reset(3 * 1000003ull);
  manisoft::rod::InverseStatics<double> statics(env.nominal_model(), {}, config.limits);
  REQUIRE(statics.solve_cold(observation.target).within_limits);
  const int inputs = manisoft::control::MlpExecutor<double>::feature_size(static_cast<int>(observation.node_indices.size()));
  std::filesystem::create_directories(scratch);
  const std::string weights = scratch + "/feedforward.txt";
  {
    std::ofstream file(weights);
    file.precision(17);
    file << "# zero weights; bias = inverse statics feed-forward (element-major)\n"
         << "manisoft-mlp 1\nlayers 1\ninput " << inputs << "\nlayer " << 3 * env.n_elements() << " linear\n";
    for (int i = 0; i < 3 * env.n_elements(); ++i) {
      for (int j = 0; j < inputs; ++j) file << "0 ";
      file << "\n";
    }
    for (int k = 0; k < env.n_elements(); ++k)
      for (int c = 0; c < 3; ++c) file << statics.feedforward()(k, c) << ' ';
    file << "\n";
  }
  const std::string out = scratch + "/mlp.csv";
  REQUIRE(run("--targets 1 --seed 3 --set equilibria --executor mlp --weights " + weights + " --damping uniform:5 --out " + out) == 0);
  CHECK_THAT(log_text(), Catch::Matchers::Contains("success: 100.0% (1 of 1)"));
  std::string header;
  const auto rows = read_csv(out, header);
  REQUIRE(rows.size() == 1);
  CAPTURE(rows[0][position_error_column], rows[0][rotation_error_column]);
  CHECK(rows[0][success_column] == 1);
  CHECK(rows[0][position_error_column] < 5e-3);
  CHECK(rows[0][rotation_error_column] < 1e-2);

  // The same policy with the wrong output count for the action space is refused with exit 1.
  CHECK(run("--targets 1 --seed 3 --set equilibria --executor mlp --weights " + weights + " --action bspline --out " + out) == 1);
  CHECK_THAT(log_text(), Catch::Matchers::Contains("the action needs 3 x 8 = 24"));
}

TEST_CASE("reach_eval drives the B-spline muscle action space", "[executor][reach_eval]") {
  const std::string out = scratch + "/bspline.csv";
  REQUIRE(run("--targets 2 --seed 1 --set table --executor model --action bspline:6 --tol-pos 0.01 --tol-rot 0.1 --out " + out) == 0);
  CHECK_THAT(log_text(), Catch::Matchers::Contains("success: 100.0% (2 of 2)"));
  std::string header;
  const auto rows = read_csv(out, header);
  REQUIRE(rows.size() == 2);
  for (const auto& row : rows) {
    CHECK(row[position_error_column] < 0.01);
    CHECK(row[rotation_error_column] < 0.1);
  }
  CHECK(header.rfind("index,target_x", 0) == 0);
}

TEST_CASE("reach_eval with a node speed bound keeps equilibria targets within the transient limits", "[executor][reach_eval]") {
  // The transient check: no node faster than 1.5 m/s, a tip path at most 1.5 x the
  // straight distance. The default ramp (250 steps at least) sweeps equilibria target 0 of seed
  // 1 (0.65 m away) at up to 3 m/s; bounded to a planned 1.25 m/s it takes longer and stays under 1.5.
  const std::string out = scratch + "/bounded.csv";
  std::string header;
  REQUIRE(run("--targets 3 --seed 1 --set equilibria --out " + out) == 0);
  double fastest_default = 0;
  for (const auto& row : read_csv(out, header)) fastest_default = std::max(fastest_default, row[node_speed_column]);
  CHECK(fastest_default > 1.5);
  REQUIRE(run("--targets 3 --seed 1 --set equilibria --max-node-speed 1.25 --out " + out) == 0);
  CHECK_THAT(log_text(), Catch::Matchers::Contains("success: 100.0% (3 of 3)"));
  const auto rows = read_csv(out, header);
  REQUIRE(rows.size() == 3);
  for (const auto& row : rows) {
    CAPTURE(row[0], row[node_speed_column], row[path_ratio_column]);
    CHECK(row[success_column] == 1);
    CHECK(row[node_speed_column] <= 1.5);
    CHECK(row[node_speed_column] >= 0.9);  // the bound slows the ramp, it does not stop the arm
    CHECK(row[path_ratio_column] <= 1.5);
  }
  CHECK(run("--seed 1 --max-node-speed 0 --out " + out) == 2);
  CHECK_THAT(log_text(), Catch::Matchers::Contains("--max-node-speed must be > 0"));
}

TEST_CASE("reach_eval refuses bad flags and malformed weight files", "[executor][reach_eval][input]") {
  const std::string out = scratch + "/bad.csv";
  CHECK(run("--seed 1 --action spline --out " + out) == 2);
  CHECK_THAT(log_text(), Catch::Matchers::Contains("--action must be elements"));
  CHECK(run("--seed 1 --action bspline:x --out " + out) == 2);
  CHECK(run("--seed 1 --executor mlp --out " + out) == 2);
  CHECK_THAT(log_text(), Catch::Matchers::Contains("needs --weights FILE"));
  CHECK(run("--seed 1 --targets 0 --out " + out) == 2);
  CHECK(run("--targets 1 --out " + out) == 2);  // no seed
  const std::string bad = scratch + "/bad_weights.txt";
  std::ofstream(bad) << "manisoft-mlp 1\nlayers 1\ninput 2\nlayer 1 linear\n1 x\n0\n";
  CHECK(run("--seed 1 --executor mlp --weights " + bad + " --out " + out) == 1);
  CHECK_THAT(log_text(), Catch::Matchers::Contains(bad + ":5"));
}

TEST_CASE("the shipped MLP executor reaches the share of the table targets BENCHMARKS.md documents", "[executor][mlp][reach_eval]") {
  // examples/data/executors/distilled_table.mlp (manisoft.sac_executor distill, exported) on
  // reach_eval's 100 table targets of seed 1: within 0.03 m / 0.3 rad once (--hold-steps 1, the
  // paper's criterion) on 71, held 100 control steps on 14 (g++ -O1, -O2 and -O3 builds). The closed
  // loop is sensitive to the last bits of the network's sums, which may differ between
  // optimisation levels and compilers: a band of five targets either way (four for the held).
  const std::string weights = MANISOFT_TEST_DATA_DIR "/../../examples/data/executors/distilled_table.mlp";
  const std::string out = scratch + "/shipped.csv";
  const auto successes = [&](int hold_steps) {
    REQUIRE(run("--targets 100 --seed 1 --set table --executor mlp --weights " + weights + " --hold-steps " + std::to_string(hold_steps) +
                " --out " + out) == 0);
    std::string header;
    const auto rows = read_csv(out, header);
    REQUIRE(rows.size() == 100);
    return std::count_if(rows.begin(), rows.end(), [](const auto& row) { return row.at(success_column) == 1.0; });
  };
  const auto reached = successes(1);
  CHECK(reached >= 66);
  CHECK(reached <= 76);
  const auto held = successes(100);
  CHECK(held >= 10);
  CHECK(held <= 18);
}
