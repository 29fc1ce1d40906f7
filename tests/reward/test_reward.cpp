// Reward components of paper section 3.4 against hand-computed values: the SE(3) pose distance
// (including a case where the V^-1 of the SE(3) logarithm changes the reward), R_d, R_s, the
// non-finite penalty and their weighted Sum.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "manisoft/core/error.hpp"
#include "manisoft/math/se3.hpp"
#include "manisoft/math/so3.hpp"
#include "manisoft/reward/distance_reward.hpp"
#include "manisoft/reward/non_finite_penalty.hpp"
#include "manisoft/reward/pose_distance.hpp"
#include "manisoft/reward/reward_term.hpp"
#include "manisoft/reward/stability_reward.hpp"
#include "manisoft/reward/sum.hpp"

namespace test_reward {  // per-file namespace: the group's tests build as one unity translation unit

namespace {

namespace math = manisoft::math;
namespace reward = manisoft::reward;
using Pose = math::Pose<double>;
using Input = reward::RewardInput<double>;

constexpr double kPi = std::numbers::pi;
constexpr double kDt = 1.0 / 714.0;  // control period of the paper, s

Approx near(double value) { return Approx(value).epsilon(0).margin(1e-12); }

math::Matrix3<double> rotation_z(double angle) { return math::so3::exp(Eigen::Vector3d(0, 0, angle)); }

/// A start pose away from the origin, so the tests also cover P != identity.
const Pose kStart{math::so3::exp(Eigen::Vector3d(0.3, -0.5, 0.7)), Eigen::Vector3d(0.4, -0.2, 0.6)};

/// Target = start moved by `offset` (in the start frame) and turned by `angle` about its z axis.
Pose target_from(const Pose& start, const Eigen::Vector3d& offset, double angle) {
  return start * Pose{rotation_z(angle), offset};
}

/// Input whose pose distance is a pure translation of `d` metres along x from the origin.
Input input_at_distance(double d) { return Input{Pose{}, Pose{.translation = Eigen::Vector3d(d, 0, 0)}, kDt}; }

}  // namespace

static_assert(reward::RewardTerm<reward::DistanceReward<double>>);
static_assert(reward::RewardTerm<reward::StabilityReward<float>>);
static_assert(reward::RewardTerm<reward::NonFinitePenalty<>>);
static_assert(!reward::RewardTerm<int>);
static_assert(!reward::RewardTerm<Pose>);

// ================================  pose distance  ================================

TEST_CASE("pose distance of a pure translation", "[reward][pose]") {
  // log(P^-1 P_hat) with no rotation is [t; 0]: d_p = 0.04, d_r = 0, d = 0.04.
  const auto error = reward::pose_error(Pose{}, Pose{.translation = Eigen::Vector3d(0.04, 0, 0)});
  CHECK(error.position_error == near(0.04));
  CHECK(error.rotation_error == near(0.0));
  CHECK(error.distance == near(0.04));
  CHECK(error.euclidean_position_error == near(0.04));
  // The same relative motion from a rotated, shifted start (left invariance): still 0.04.
  const auto moved = reward::pose_error(kStart, target_from(kStart, Eigen::Vector3d(0, 0.04, 0), 0.0));
  CHECK(moved.position_error == near(0.04));
  CHECK(moved.distance == near(0.04));
  CHECK(moved.euclidean_position_error == near(0.04));
}

TEST_CASE("pose distance of a pure rotation", "[reward][pose]") {
  // 0.2 rad about z: d_p = 0, d_r = 0.2, d = alpha * 0.2 = 0.2 * 0.2 = 0.04.
  const auto error = reward::pose_error(kStart, target_from(kStart, Eigen::Vector3d::Zero(), 0.2));
  CHECK(error.position_error == near(0.0));
  CHECK(error.rotation_error == near(0.2));
  CHECK(error.distance == near(0.04));
  CHECK(error.euclidean_position_error == near(0.0));
  // alpha = 1.5: d = 1.5 * 0.2 = 0.3.
  CHECK(reward::pose_error(kStart, target_from(kStart, Eigen::Vector3d::Zero(), 0.2), 1.5).distance == near(0.3));
}

TEST_CASE("pose distance uses the screw translation V^-1 t, not t", "[reward][pose]") {
  // Quarter turn about z and t = (1, 0, 0) in the start frame. By hand (theta = pi/2):
  //   phi x t = (0, theta, 0), phi x (phi x t) = (-theta^2, 0, 0),
  //   e = 1/theta^2 - (1 + cos theta)/(2 theta sin theta) = 4/pi^2 - 1/pi,
  //   d_p = V^-1 t = t - 1/2 phi x t + e phi x (phi x t) = (1 - e theta^2, -theta/2, 0)
  //       = (pi/4, -pi/4, 0),   |d_p| = pi sqrt(2)/4 = 1.1107207345,
  //   d = 1.1107207345 + 0.2 * pi/2 = 1.4248799999.
  // The straight-line distance |p - p_hat| is 1.
  const auto error = reward::pose_error(kStart, target_from(kStart, Eigen::Vector3d(1, 0, 0), kPi / 2));
  CHECK(error.position_error == near(kPi * std::sqrt(2.0) / 4));
  CHECK(error.rotation_error == near(kPi / 2));
  CHECK(error.distance == near(kPi * std::sqrt(2.0) / 4 + 0.2 * kPi / 2));
  CHECK(error.euclidean_position_error == near(1.0));
  const math::Vector6<double> twist =
      reward::pose_difference(kStart, target_from(kStart, Eigen::Vector3d(1, 0, 0), kPi / 2));
  CHECK(twist(0) == near(kPi / 4));
  CHECK(twist(1) == near(-kPi / 4));
  CHECK(twist(5) == near(kPi / 2));
  CHECK_FALSE(reward::is_success(error));
}

TEST_CASE("the executor success criterion", "[reward][pose]") {
  // Thresholds d_p < 0.03 m and d_r < 0.3 rad, strict.
  CHECK(reward::is_success(reward::pose_error(Pose{}, Pose{.translation = Eigen::Vector3d(0, 0.029, 0)})));
  CHECK_FALSE(reward::is_success(reward::pose_error(Pose{}, Pose{.translation = Eigen::Vector3d(0, 0.031, 0)})));
  CHECK(reward::is_success(reward::pose_error(kStart, target_from(kStart, Eigen::Vector3d::Zero(), 0.29))));
  CHECK_FALSE(reward::is_success(reward::pose_error(kStart, target_from(kStart, Eigen::Vector3d::Zero(), 0.31))));
  // Both at once: 0.02 m along x and 0.25 rad about z. d_p = 0.02 * sqrt((1 - e th^2)^2 + th^2/4)
  // with th = 0.25 is 0.02 * 1.0026 = 0.02005 < 0.03: success.
  CHECK(reward::is_success(reward::pose_error(kStart, target_from(kStart, Eigen::Vector3d(0.02, 0, 0), 0.25))));
  // Tighter tolerance.
  CHECK_FALSE(reward::is_success(reward::pose_error(Pose{}, Pose{.translation = Eigen::Vector3d(0, 0.02, 0)}),
                                 reward::SuccessTolerance<double>{0.01, 0.1}));
}

TEST_CASE("pose distance refuses a non-positive alpha", "[reward][pose]") {
  CHECK_THROWS_WITH(reward::pose_error(Pose{}, Pose{}, 0.0), Catch::Contains("alpha"));
  CHECK_THROWS_WITH(reward::pose_error(Pose{}, Pose{}, -0.2), Catch::Contains("alpha"));
}

// ================================  R_d  ================================

TEST_CASE("DistanceReward matches hand-computed values", "[reward][distance]") {
  reward::DistanceReward<double> r_d;  // alpha 0.2, lambda 1, k1 0.5, k2 1.5: d1 = 0.1, d2 = 0.05
  CHECK(r_d.first_threshold() == near(0.1));
  CHECK(r_d.second_threshold() == near(0.05));

  // Pure translation 0.04 m: d = 0.04 < d2 < d1, R_d = -0.04 + 0.5 + 1.5 = 1.96.
  auto result = r_d.evaluate(input_at_distance(0.04));
  CHECK(result.value == near(1.96));
  CHECK_FALSE(result.done);
  // Pure rotation 0.2 rad: d = 0.2 * 0.2 = 0.04, the same R_d = 1.96.
  CHECK(r_d.evaluate(Input{kStart, target_from(kStart, Eigen::Vector3d::Zero(), 0.2), kDt}).value == near(1.96));
  // d = 0.07: only the first bonus, R_d = -0.07 + 0.5 = 0.43.
  CHECK(r_d.evaluate(input_at_distance(0.07)).value == near(0.43));
  // d = 0.1 exactly: the indicators are strict, R_d = -0.1.
  CHECK(r_d.evaluate(input_at_distance(0.1)).value == near(-0.1));
  // d = 0.05 exactly: only k1, R_d = -0.05 + 0.5 = 0.45.
  CHECK(r_d.evaluate(input_at_distance(0.05)).value == near(0.45));
  // d = 2: R_d = -2.
  CHECK(r_d.evaluate(input_at_distance(2.0)).value == near(-2.0));
}

TEST_CASE("DistanceReward where V^-1 decides the bonus", "[reward][distance]") {
  // theta = 0.2 rad about z, t = (a, 0, 0) with a = 0.00999 m, in the start frame. By hand:
  //   e = 1/theta^2 - (1 + cos theta)/(2 theta sin theta) = 25 - 24.9166111 = 0.0833889,
  //   d_p = (a (1 - e theta^2), -a theta/2, 0),
  //   |d_p| = a sqrt((1 - e theta^2)^2 + theta^2/4) = 0.00999 * 1.0016686 = 0.0100067,
  //   d = 0.0100067 + 0.2 * 0.2 = 0.0500067 >= d2 = 0.05, so only k1:
  //   R_d = -0.0500067 + 0.5 = 0.4499933.
  // With the straight-line |t| = 0.00999 instead, d would be 0.04999 and R_d 1.95001.
  const double theta = 0.2;
  const double a = 0.00999;
  const double e = 1.0 / (theta * theta) - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  const double position = a * std::sqrt(std::pow(1.0 - e * theta * theta, 2) + theta * theta / 4.0);
  REQUIRE(position == Approx(0.0100067).epsilon(1e-5));

  const Input input{kStart, target_from(kStart, Eigen::Vector3d(a, 0, 0), theta), kDt};
  const auto error = reward::pose_error(input.end_effector, input.target);
  CHECK(error.position_error == near(position));
  CHECK(error.euclidean_position_error == near(a));
  CHECK(error.distance == near(position + 0.2 * theta));
  CHECK(reward::DistanceReward<double>{}.evaluate(input).value == near(0.5 - (position + 0.2 * theta)));
  CHECK(reward::DistanceReward<double>{}.evaluate(input).value == near(0.4499933305545));
}

TEST_CASE("DistanceReward parameters", "[reward][distance]") {
  // lambda = 2: d1 = 0.05, d2 = 0.025. d = 0.04: R_d = -0.04 + 0.5 = 0.46.
  reward::DistanceReward<double> scaled({.lambda = 2.0});
  CHECK(scaled.evaluate(input_at_distance(0.04)).value == near(0.46));
  // k1 = 1, k2 = 3, alpha = 1: rotation 0.04 rad gives d = 0.04, R_d = -0.04 + 1 + 3 = 3.96.
  reward::DistanceReward<double> custom({.alpha = 1.0, .k1 = 1.0, .k2 = 3.0});
  CHECK(custom.evaluate(Input{kStart, target_from(kStart, Eigen::Vector3d::Zero(), 0.04), kDt}).value ==
        near(3.96));
  CHECK_THROWS_WITH(reward::DistanceReward<double>({.alpha = 0.0}), Catch::Contains("alpha"));
  CHECK_THROWS_WITH(reward::DistanceReward<double>({.lambda = -1.0}), Catch::Contains("lambda"));
  CHECK_THROWS_WITH(reward::DistanceReward<double>({.k1 = std::numeric_limits<double>::quiet_NaN()}), Catch::Contains("k1"));
  // A non-finite target is the caller's bug: refused.
  Input bad_target = input_at_distance(0.04);
  bad_target.target.translation.x() = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(reward::DistanceReward<double>{}.evaluate(bad_target), Catch::Contains("target"));
}

TEST_CASE("DistanceReward in float", "[reward][distance]") {
  reward::DistanceReward<float> r_d;
  const reward::RewardInput<float> input{math::Pose<float>{},
                                         math::Pose<float>{.translation = Eigen::Vector3f(0.04f, 0, 0)}, 1e-3f};
  CHECK(r_d.evaluate(input).value == Approx(1.96f).margin(1e-6));
}

// ================================  R_s  ================================

TEST_CASE("StabilityReward follows the sign of dd/dt inside D", "[reward][stability]") {
  reward::StabilityReward<double> r_s;  // beta 1, D 0.3
  // First step after construction: no previous d, so no rate: 0.
  CHECK(r_s.evaluate(input_at_distance(0.25)).value == 0.0);
  // 0.25 -> 0.20, d <= D, dd/dt < 0: R_s = -sgn(-) * 1 = +1.
  CHECK(r_s.evaluate(input_at_distance(0.20)).value == 1.0);
  // 0.20 -> 0.22, dd/dt > 0: R_s = -1.
  CHECK(r_s.evaluate(input_at_distance(0.22)).value == -1.0);
  // 0.22 -> 0.22, dd/dt = 0: sgn(0) = 0.
  CHECK(r_s.evaluate(input_at_distance(0.22)).value == 0.0);
  // 0.22 -> 0.50, d > D: 0 (even though d grew).
  CHECK(r_s.evaluate(input_at_distance(0.50)).value == 0.0);
  // 0.50 -> 0.40, still d > D: 0 (even though d shrank).
  CHECK(r_s.evaluate(input_at_distance(0.40)).value == 0.0);
  // 0.40 -> 0.29, now d <= D and shrinking: +1 (the rate uses the previous d from outside D).
  CHECK(r_s.evaluate(input_at_distance(0.29)).value == 1.0);
  // 0.29 -> 0.30 = D exactly (d <= D holds) and growing: -1.
  CHECK(r_s.evaluate(input_at_distance(0.30)).value == -1.0);
  // After reset() the previous d is forgotten: 0 again, whatever the last value was.
  r_s.reset();
  CHECK(r_s.evaluate(input_at_distance(0.10)).value == 0.0);
  CHECK(r_s.evaluate(input_at_distance(0.05)).value == 1.0);
}

TEST_CASE("StabilityReward parameters and the rotation part of d", "[reward][stability]") {
  // beta = 2, D = 0.1, alpha = 0.5: rotations 0.1 -> 0.15 rad give d = 0.05 -> 0.075 (<= D,
  // growing): R_s = -2. Then 0.15 -> 0.3 rad gives d = 0.15 > D: 0.
  reward::StabilityReward<double> r_s({.alpha = 0.5, .beta = 2.0, .distance_threshold = 0.1});
  auto turned = [](double angle) { return Input{kStart, target_from(kStart, Eigen::Vector3d::Zero(), angle), kDt}; };
  CHECK(r_s.evaluate(turned(0.1)).value == 0.0);
  CHECK(r_s.evaluate(turned(0.15)).value == -2.0);
  CHECK(r_s.evaluate(turned(0.3)).value == 0.0);
  // dt must be positive.
  Input no_time = input_at_distance(0.1);
  no_time.dt = 0.0;
  CHECK_THROWS_WITH(r_s.evaluate(no_time), Catch::Contains("dt"));
  CHECK_THROWS_WITH(reward::StabilityReward<double>({.beta = -1.0}), Catch::Contains("beta"));
}

// ================================  non-finite penalty  ================================

TEST_CASE("NonFinitePenalty ends the episode on a non-finite state", "[reward][penalty]") {
  reward::NonFinitePenalty<double> penalty;
  auto result = penalty.evaluate(input_at_distance(0.1));
  CHECK(result.value == 0.0);
  CHECK_FALSE(result.done);

  Input diverged = input_at_distance(0.1);
  diverged.state_is_finite = false;
  result = penalty.evaluate(diverged);
  CHECK(result.value == -1000.0);
  CHECK(result.done);

  // A NaN in the end-effector pose counts as a non-finite state even if the flag was not set.
  Input nan_pose = input_at_distance(0.1);
  nan_pose.end_effector.rotation(1, 2) = std::numeric_limits<double>::quiet_NaN();
  CHECK(penalty.evaluate(nan_pose).done);
  CHECK(reward::NonFinitePenalty<double>(-50.0).evaluate(nan_pose).value == -50.0);
  CHECK_THROWS_WITH(reward::NonFinitePenalty<double>(std::numeric_limits<double>::infinity()), Catch::Contains("NonFinitePenalty penalty = inf"));
}

// ================================  Sum  ================================

TEST_CASE("Sum weighs and evaluates every term", "[reward][sum]") {
  using Reward = reward::Sum<reward::DistanceReward<double>, reward::StabilityReward<double>,
                             reward::NonFinitePenalty<double>>;
  static_assert(Reward::size == 3);
  Reward total({1.0, 0.5, 1.0}, reward::DistanceReward<double>{}, reward::StabilityReward<double>{},
               reward::NonFinitePenalty<double>{});
  CHECK(total.weights()[1] == 0.5);

  // Step 1, d = 0.04: R_d = 1.96, R_s = 0 (first step), penalty 0. Total = 1.96.
  auto result = total.evaluate(input_at_distance(0.04));
  CHECK(result.values[0] == near(1.96));
  CHECK(result.values[1] == 0.0);
  CHECK(result.values[2] == 0.0);
  CHECK(result.total == near(1.96));
  CHECK_FALSE(result.done);

  // Step 2, d = 0.03: R_d = -0.03 + 0.5 + 1.5 = 1.97, R_s = +1 (shrinking, d <= 0.3).
  // Total = 1 * 1.97 + 0.5 * 1 + 1 * 0 = 2.47.
  result = total.evaluate(input_at_distance(0.03));
  CHECK(result.values[0] == near(1.97));
  CHECK(result.values[1] == 1.0);
  CHECK(result.total == near(2.47));
  CHECK_FALSE(result.done);

  // Step 3, the simulation diverged: R_d = R_s = 0, penalty -1000, done.
  Input diverged = input_at_distance(0.03);
  diverged.state_is_finite = false;
  result = total.evaluate(diverged);
  CHECK(result.values[0] == 0.0);
  CHECK(result.values[1] == 0.0);
  CHECK(result.values[2] == -1000.0);
  CHECK(result.total == -1000.0);
  CHECK(result.done);

  // reset() reaches every term: the stability term has no previous d again.
  total.reset();
  result = total.evaluate(input_at_distance(0.02));
  CHECK(result.values[1] == 0.0);
  CHECK(result.total == near(-0.02 + 2.0));
  // The terms are reachable, e.g. for their parameters.
  CHECK(total.term<0>().first_threshold() == near(0.1));
}

TEST_CASE("Sum with default terms and weights", "[reward][sum]") {
  reward::Sum<reward::DistanceReward<>, reward::StabilityReward<>> paper_reward;  // R = R_d + R_s
  CHECK(paper_reward.weights()[0] == 1.0);
  CHECK(paper_reward.weights()[1] == 1.0);
  CHECK(paper_reward.evaluate(input_at_distance(0.2)).total == near(-0.2));
  // 0.2 -> 0.25: R_d = -0.25, R_s = -1. R = -1.25.
  CHECK(paper_reward.evaluate(input_at_distance(0.25)).total == near(-1.25));

  using One = reward::Sum<reward::NonFinitePenalty<>>;
  CHECK_THROWS_WITH(One({std::numeric_limits<double>::quiet_NaN()}, reward::NonFinitePenalty<>{}),
                    Catch::Contains("weight[0]"));
}

}  // namespace test_reward
