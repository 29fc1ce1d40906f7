// The batched reach environment against single ReachEnvs stepped alone with the same seeds and
// actions (bit-identical per arm at batch sizes 1, 3 and 64, one and two threads), its reset mask,
// the NEXT_STEP autoreset, bad actions refused per arm with nothing changed, no allocation in a
// step, and the worker pool handing a worker's exception to the caller.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "manisoft/core/worker_pool.hpp"
#include "manisoft/env/batched_reach_env.hpp"

#include "../support/allocation_counter.hpp"  // after Eigen: it replaces the allocation functions mm_malloc.h declares

namespace test_batched_reach_env {  // per-file namespace: the group's tests build as one unity translation unit

namespace {

using Batch = manisoft::env::BatchedReachEnv<>;
using Env = Batch::Env;
using Array3 = Env::Array3;
using Damping = manisoft::rod::damping::AnalyticalLinear<double>;

manisoft::env::ReachEnvConfig small_config(int horizon = 1500) {
  manisoft::env::ReachEnvConfig c;
  c.horizon = horizon;
  return c;
}

/// A mild action, different per arm and per step (a few N m, well inside the limits).
Array3 action_of(int arm, int t, int rows) {
  Array3 a(rows, 3);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < 3; ++c) a(r, c) = 4.0 * std::sin(0.3 * t + 0.7 * arm + 0.5 * r + 1.3 * c);
  return a;
}

/// The batch's action array (B x rows x 3, row-major) from one action per arm.
std::vector<double> pack(const std::vector<Array3>& per_arm) {
  std::vector<double> out;
  for (const Array3& a : per_arm)
    for (int r = 0; r < a.rows(); ++r)
      for (int c = 0; c < 3; ++c) out.push_back(a(r, c));
  return out;
}

std::vector<double> batch_actions(int batch, int t, int rows) {
  std::vector<Array3> per_arm;
  for (int i = 0; i < batch; ++i) per_arm.push_back(action_of(i, t, rows));
  return pack(per_arm);
}

/// A copy of a batch's arrays after one call, read through the same accessors.
struct Recorded {
  explicit Recorded(const Batch& b)
      : observed(b.observed_nodes()), ee(copy(b.end_effector())), tg(copy(b.target())), np(copy(b.node_positions())),
        nv(copy(b.node_velocities())), rw(copy(b.rewards())), pe(copy(b.position_error())), re(copy(b.rotation_error())),
        ms(copy(b.max_node_speed())), te(copy(b.terminated())), tr(copy(b.truncated())), su(copy(b.success())),
        st(copy(b.steps())), cl(copy(b.clipped())), sd(copy(b.seeds())) {}
  template <typename T>
  static std::vector<T> copy(std::span<const T> s) { return std::vector<T>(s.begin(), s.end()); }
  int observed;
  std::vector<double> ee, tg, np, nv, rw, pe, re, ms;
  std::vector<std::uint8_t> te, tr, su;
  std::vector<std::int32_t> st, cl;
  std::vector<std::uint64_t> sd;
  int observed_nodes() const { return observed; }
  std::span<const double> end_effector() const { return ee; }
  std::span<const double> target() const { return tg; }
  std::span<const double> node_positions() const { return np; }
  std::span<const double> node_velocities() const { return nv; }
  std::span<const double> rewards() const { return rw; }
  std::span<const double> position_error() const { return pe; }
  std::span<const double> rotation_error() const { return re; }
  std::span<const double> max_node_speed() const { return ms; }
  std::span<const std::uint8_t> terminated() const { return te; }
  std::span<const std::uint8_t> truncated() const { return tr; }
  std::span<const std::uint8_t> success() const { return su; }
  std::span<const std::int32_t> steps() const { return st; }
  std::span<const std::int32_t> clipped() const { return cl; }
  std::span<const std::uint64_t> seeds() const { return sd; }
};

/// Arm i's slice of the batch arrays equals the single environment's observation, bit for bit.
template <typename View>
void check_observation(const View& batch, int i, const manisoft::control::Observation<double>& o) {
  const double* ee = batch.end_effector().data() + 16 * i;
  const double* target = batch.target().data() + 16 * i;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      CHECK(ee[4 * r + c] == o.end_effector.rotation(r, c));
      CHECK(target[4 * r + c] == o.target.rotation(r, c));
    }
    CHECK(ee[4 * r + 3] == o.end_effector.translation(r));
    CHECK(target[4 * r + 3] == o.target.translation(r));
  }
  CHECK(ee[15] == 1.0);
  CHECK(ee[12] == 0.0);
  const int m = batch.observed_nodes();
  REQUIRE(m == o.node_positions.rows());
  for (int k = 0; k < m; ++k)
    for (int c = 0; c < 3; ++c) {
      CHECK(batch.node_positions()[std::size_t((i * m + k) * 3 + c)] == o.node_positions(k, c));
      CHECK(batch.node_velocities()[std::size_t((i * m + k) * 3 + c)] == o.node_velocities(k, c));
    }
}

/// Arm i's step outputs equal the single environment's step result, bit for bit.
template <typename View>
void check_step(const View& batch, int i, const Env::StepResult& s, int horizon) {
  CAPTURE(i, s.info.step);
  check_observation(batch, i, s.observation);
  const auto k = std::size_t(i);
  CHECK(batch.rewards()[k] == s.reward);
  CHECK(batch.terminated()[k] == (s.info.diverged ? 1 : 0));
  CHECK(batch.truncated()[k] == (!s.info.diverged && s.info.step >= horizon ? 1 : 0));
  CHECK(batch.success()[k] == (s.info.success ? 1 : 0));
  CHECK(batch.steps()[k] == s.info.step);
  CHECK(batch.position_error()[k] == s.info.error.position_error);
  CHECK(batch.rotation_error()[k] == s.info.error.rotation_error);
  CHECK(batch.clipped()[k] == s.info.clipped);
  CHECK(batch.max_node_speed()[k] == s.info.max_node_speed);
}

/// Arm i is at the start of the episode of `seed`.
template <typename View>
void check_reset(const View& batch, int i, std::uint64_t seed, const manisoft::control::Observation<double>& o) {
  const auto k = std::size_t(i);
  check_observation(batch, i, o);
  CHECK(batch.seeds()[k] == seed);
  CHECK(batch.rewards()[k] == 0.0);
  CHECK(batch.steps()[k] == 0);
  CHECK(batch.terminated()[k] == 0);
  CHECK(batch.truncated()[k] == 0);
  CHECK(batch.success()[k] == 0);
}

/// A copy of every output array, to check that a refused call changed nothing.
std::vector<double> snapshot(const Batch& b) {
  std::vector<double> out;
  for (auto span : {b.end_effector(), b.target(), b.node_positions(), b.node_velocities(), b.rewards(), b.position_error()})
    out.insert(out.end(), span.begin(), span.end());
  for (std::size_t i = 0; i < std::size_t(b.batch_size()); ++i) {
    out.push_back(b.steps()[i]);
    out.push_back(b.truncated()[i]);
    out.push_back(double(b.seeds()[i]));
  }
  return out;
}

/// Steps B arms on `threads` threads and replays arms of it alone, each in a fresh environment.
void check_against_single(int batch_size, int threads) {
  CAPTURE(batch_size, threads);
  const int steps = batch_size == 64 ? 2 : 10;
  Batch batch(batch_size, threads, small_config(), Damping(0.1));
  REQUIRE(batch.action_rows() == 20);
  std::vector<std::uint64_t> seeds;
  for (int i = 0; i < batch_size; ++i) seeds.push_back(std::uint64_t(1000 + 7 * i));
  batch.reset(seeds);
  std::vector<Recorded> record{Recorded(batch)};
  for (int t = 0; t < steps; ++t) {
    batch.step(batch_actions(batch_size, t, batch.action_rows()));
    record.emplace_back(batch);
  }
  // Each arm replayed alone in a fresh environment (a ReachEnv's target draw starts from its
  // inverse statics' last solution: the same seeds in the same order give the same targets). At
  // 64 arms: the first, last and neighbouring arms of each thread's chunk (0-31, 32-63).
  const std::vector<int> all{0, 1, 2}, sample{0, 1, 30, 31, 32, 33, 62, 63};
  for (const int i : batch_size == 64 ? sample : all) {
    if (i >= batch_size) continue;
    Env single(small_config(), Damping(0.1));
    check_reset(record[0], i, seeds[std::size_t(i)], single.reset(seeds[std::size_t(i)]));
    for (int t = 0; t < steps; ++t) check_step(record[std::size_t(t) + 1], i, single.step(action_of(i, t, batch.action_rows())), 1500);
  }
  CHECK(batch.steps()[0] == steps);
}

}  // namespace

TEST_CASE("batched arms step bit-identically to single reach environments", "[env][batch]") {
  const std::pair<int, int> shape = GENERATE(std::pair{1, 1}, std::pair{1, 2}, std::pair{3, 1}, std::pair{3, 2});
  check_against_single(shape.first, shape.second);
}

// 64 arms build 64 inverse-statics start libraries: seconds in an optimised build, minutes under
// the sanitizers, where 3 arms on 2 threads cover the same code (hidden there: run with its name).
#if defined(MANISOFT_TEST_SANITIZED)
#define MANISOFT_TEST_BATCH64_TAGS "[env][batch][.]"
#else
#define MANISOFT_TEST_BATCH64_TAGS "[env][batch]"
#endif
TEST_CASE("64 batched arms on two threads step bit-identically to single reach environments", MANISOFT_TEST_BATCH64_TAGS) {
  check_against_single(64, 2);
}

TEST_CASE("a reset mask restarts only the masked arms", "[env][batch]") {
  Batch batch(3, 2, small_config(), Damping(0.1));
  batch.reset(std::vector<std::uint64_t>{1, 2, 3});
  Env arm0(small_config(), Damping(0.1)), arm1(small_config(), Damping(0.1));
  arm0.reset(1);
  arm1.reset(2);  // the same seeds in the same order as the batch's arm 1
  for (int t = 0; t < 2; ++t) {
    batch.step(batch_actions(3, t, 20));
    arm0.step(action_of(0, t, 20));
  }
  const std::vector<double> arm2_before(batch.node_positions().begin() + 2 * batch.observed_nodes() * 3, batch.node_positions().end());
  batch.reset(std::vector<std::uint8_t>{0, 1, 0}, std::vector<std::uint64_t>{99, 50, 99});
  check_reset(batch, 1, 50, arm1.reset(50));
  CHECK(batch.seeds()[0] == 1);
  CHECK(batch.seeds()[2] == 3);
  CHECK(batch.steps()[0] == 2);
  CHECK(batch.steps()[2] == 2);
  CHECK(std::vector<double>(batch.node_positions().begin() + 2 * batch.observed_nodes() * 3, batch.node_positions().end()) == arm2_before);
  batch.step(batch_actions(3, 2, 20));
  check_step(batch, 0, arm0.step(action_of(0, 2, 20)), 1500);
  check_step(batch, 1, arm1.step(action_of(1, 2, 20)), 1500);
  CHECK(batch.steps()[2] == 3);
}

TEST_CASE("an ended episode is reset by the next step (NEXT_STEP autoreset)", "[env][batch]") {
  const int horizon = 5;
  Batch batch(2, 2, small_config(horizon), Damping(0.1));
  batch.reset(std::vector<std::uint64_t>{7, 8});
  Env single(small_config(horizon), Damping(0.1));
  single.reset(7);
  for (int t = 0; t < horizon; ++t) {
    batch.step(batch_actions(2, t, 20));
    check_step(batch, 0, single.step(action_of(0, t, 20)), horizon);
  }
  CHECK(batch.truncated()[0] == 1);
  CHECK(batch.truncated()[1] == 1);
  CHECK(batch.terminated()[0] == 0);
  // The ended arms' actions are ignored: not even a NaN is refused.
  std::vector<double> actions = batch_actions(2, horizon, 20);
  actions[0] = std::numeric_limits<double>::quiet_NaN();
  batch.step(actions);
  check_reset(batch, 0, 7 + 2, single.reset(9));  // the next seed: the ended one plus B = 2
  Env second(small_config(horizon), Damping(0.1));
  second.reset(8);
  check_reset(batch, 1, 8 + 2, second.reset(10));
  batch.step(batch_actions(2, 0, 20));
  check_step(batch, 0, single.step(action_of(0, 0, 20)), horizon);
  check_step(batch, 1, second.step(action_of(1, 0, 20)), horizon);
}

TEST_CASE("bad batched input is refused naming the arm, with nothing changed", "[env][batch]") {
  Batch batch(3, 2, small_config(), Damping(0.1));
  CHECK_THROWS_WITH(batch.step(batch_actions(3, 0, 20)), Catch::Contains("before reset"));
  CHECK_THROWS_AS(batch.reset(std::vector<std::uint64_t>{1, 2}), manisoft::InvalidInput);
  batch.reset(std::vector<std::uint64_t>{1, 2, 3});
  const std::vector<double> before = snapshot(batch);
  std::vector<double> actions = batch_actions(3, 0, 20);
  actions[2 * 60 + 4 * 3 + 1] = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(batch.step(actions), Catch::Contains("arm 2: action entry (4, 1) = inf is not finite"));
  CHECK_THROWS_AS(batch.step(actions), manisoft::InvalidInput);
  CHECK_THROWS_WITH(batch.step(std::vector<double>(59, 0.0)), Catch::Contains("actions hold 59 values, expected batch_size x rows x 3 = 3 x 20 x 3 = 180"));
  CHECK_THROWS_WITH(batch.reset(std::vector<std::uint8_t>{1, 0}, std::vector<std::uint64_t>{1, 2, 3}),
                    Catch::Contains("mask hold 2 values, expected batch_size = 3"));
  CHECK(snapshot(batch) == before);
  // Nothing advanced: the next good step is every arm's first.
  batch.step(batch_actions(3, 0, 20));
  Env single(small_config(), Damping(0.1));
  single.reset(3);
  check_step(batch, 2, single.step(action_of(2, 0, 20)), 1500);
}

TEST_CASE("a batched step allocates no heap memory", "[env][batch][alloc]") {
  const int threads = GENERATE(1, 2);
  Batch batch(2, threads, small_config(), Damping(0.1));
  batch.reset(std::vector<std::uint64_t>{1, 2});
  const std::vector<double> actions = batch_actions(2, 0, 20);
  batch.step(actions);
  const long before = manisoft_test::allocation_count.load();
  for (int t = 0; t < 20; ++t) batch.step(actions);
  CHECK(manisoft_test::allocation_count.load() - before == 0);
  CHECK(batch.steps()[1] == 21);
}

TEST_CASE("a worker's exception reaches the caller and the pool runs on", "[env][batch]") {
  manisoft::WorkerPool pool(3);
  std::vector<int> ran(3, 0);
  auto failing = [&](int part, int parts) {
    ran[std::size_t(part)] = parts;
    if (part == 2) manisoft::detail::fail("part ", part, " failed");
  };
  CHECK_THROWS_WITH(pool.run(failing), "part 2 failed");
  CHECK(ran == std::vector<int>{3, 3, 3});
  auto counting = [&](int part, int) { ran[std::size_t(part)] = 10 + part; };
  pool.run(counting);
  CHECK(ran == std::vector<int>{10, 11, 12});
  auto two = [&](int part, int parts) { ran[std::size_t(part)] = 20 + parts; };
  pool.run(two, 2);  // the third part's worker does nothing
  CHECK(ran == std::vector<int>{22, 22, 12});
  CHECK_THROWS_WITH(pool.run(two, 4), Catch::Contains("parts = 4 must be in [1, threads = 3]"));
  // Jobs of 2, 1 and 3 parts in a row: a worker left out of one job wakes during the next.
  int sum = 0;
  for (int round = 0; round < 300; ++round) {
    std::vector<int> hits(3, 0);
    auto count = [&](int part, int) { ++hits[std::size_t(part)]; };
    const int parts = 1 + round % 3;
    pool.run(count, parts);
    for (int part = 0; part < 3; ++part) sum += hits[std::size_t(part)] == (part < parts ? 1 : 0);
  }
  CHECK(sum == 900);
  CHECK_THROWS_WITH(manisoft::WorkerPool(0), Catch::Contains("threads = 0 must be >= 1"));
}

}  // namespace test_batched_reach_env
