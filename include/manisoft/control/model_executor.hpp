// Model-based executor (the low-level executor of the ManiSoft paper, section 3.4): inverse statics feed-forward, node
// velocity and position feedback mapped to element torques, an online estimate of the arm's
// stiffness scale, and an outer loop on the measured end-effector pose.
//
// Model it assumes (rod::ArmModel): a uniform clamped Cosserat rod with known rest geometry,
// density and Young's/shear moduli, uniform gravity, and a known point payload on the tip node
// (the gripper); the end-effector frame is the tip frame (last node, last element's directors).
// A stiffness error is estimated online (below); anything else (an unknown held load, the
// damping of the simulated rod) is left to the feedback and the outer loop.
//
// Per control step, action = clamp(tau_ff + tau_fb), element 0 (clamped) = 0; from the tip
// inwards, what the clamp cuts off an element is added to the next proximal element
// (carry_saturation): the couple carried across every other node is then still the one asked for
// (sum_{j >= k} tau_j), only the node between the two elements sees the difference (without it,
// targets near the limits slip into a slow saturated oscillation).
//   tau_ff    the inverse statics feed-forward of the current shape target (inverse_statics.hpp),
//             with the elastic part scaled by the stiffness estimate s_hat;
//   tau_fb    node forces F_j = -m_j (kd v_j + kp (x_j - x*_j)) (positions and velocities of
//             unobserved nodes interpolated linearly between observed ones; the tip node carries
//             the payload mass too) turned into the statically equivalent element couples. A set
//             of couples m_i is equivalent to node forces F_j when it gives the same moment at
//             every cross-section:
//               m_k = (x_{k+1} - x_k) x sum_{j > k} F_j        (lab; to material with Q_k),
//             the same lever-arm form as the rod's own shear couple (Q t x n) l0. Q_k is the
//             desired director turned by the smallest rotation taking the desired element
//             tangent onto the observed one. The position term matters beyond steady-state
//             accuracy: the feed-forward torques are follower (material-frame) loads, and on
//             strongly curled shapes the equilibrium they hold flutters unless the feedback is
//             stiff enough.
//   twist     the position feedback cannot see twist: a twist couple -k_tw phi (s_k / L) on every
//             element, phi the twist of the observed end-effector frame about the tip tangent
//             relative to the estimated tip frame, holds the twist of curled shapes (without it
//             strongly curled shapes can twist off to another equilibrium branch).
//   ramp      a new target's shape is reached through the coefficient blend of the old and new
//             inverse statics solutions (smoothstep) over max(ramp_steps, tip path / ramp_max_speed)
//             control steps (at most max_ramp_steps): a blend whose tip sweeps a long path (it
//             can be several times the arm's length) is slowed so the arm can follow it.
//             Options (off by default; ModelExecutorSettings::smooth_ramp turns them on):
//             ramp_max_node_step lengthens the ramp until no node's planned speed (the largest
//             node displacement between samples of the timed blend) exceeds it; ramp_path_ratio
//             puts via shapes into a blend whose tip path is longer than that ratio x the
//             straight distance (the blend's midpoint shape with its tip pulled onto the straight
//             line and re-solved near it, recursively; the ramp then runs piecewise linearly
//             through them, each segment's share of the time proportional to its largest node
//             path); when they leave the blend's tip path longer than ramp_path_ratio x the straight
//             distance, line vias instead (tips evenly on the straight line, rotation free,
//             actuation relieved: try_line_vias); ramp_cruise replaces smoothstep by track_line's
//             cruise timing.
//   stiffness estimate (after the ramp, while every observed node is slower than
//             estimate_speed_gate and no actuator saturates): a stiffness error s/s_hat bends the arm, to first order, to
//             the curvature (s_hat/s) c* of the desired one. Every `outer_period` steps the
//             observed node deviations (and the tip rotation deviation) averaged over the period
//             are regressed on the shape change of a relative curvature scaling, beta, and
//             s_hat <- s_hat (1 - g beta). With the right s_hat the desired shape is again an exact
//             equilibrium of the arm. freeze_estimate() holds it while the tool presses on
//             something the model does not include.
//   outer loop every `outer_period` control steps while quasi-static: with the pose error
//             averaged over the period, e_p = p* - p, e_R = log(R* R^T) (lab), the shape target
//             moves by  p_s <- p_s + K e_p,  R_s <- Exp(K e_R) R_s,  and the inverse statics is
//             re-solved (warm started) for the shifted target: integral action on the SE(3) tip
//             error for what the stiffness estimate does not explain (an unknown load).
//   tracking (track_line): the executor follows a time-parameterised SE(3) path, a straight
//             line from the current shape target's tip pose to a goal (position linear, rotation
//             along the geodesic) with quintic (minimum-jerk) timing over a given number of
//             control steps. At set-up the path is cut into knots (at most knot_spacing m or
//             knot_angle rad apart, at least one per max_knot_steps) and the inverse statics is
//             solved at each knot warm-started from the previous knot's shape (solve_near: the
//             smallest shape change, relieving actuators that near their limits), so the shape target
//             moves continuously with the path and never restarts a ramp; between knots the
//             curvature coefficients are interpolated linearly in time. Continuity check: the tip
//             path of each knot-to-knot blend (sampled) must stay within path_ratio_limit times
//             the straight distance (plus 1 mm); a knot that fails it (or does not converge within
//             the limits) is subdivided, up to max_subdivisions times, else the whole path is
//             refused and reported (PathReport) and the executor keeps its current shape target.
//             A point target is a path of length zero. While tracking, the node velocity feedback
//             acts on v - v*, v* the desired shape's node velocity (finite difference along the
//             schedule), so the arm is not braked against the motion it is asked to make.
//   payload   set_payload(m, r): a held object of mass m whose centre is at r in the
//             end-effector frame; the feed-forward adds its weight at the tip (the shear couple of
//             inverse_statics.hpp) and cancels its couple r x m g on the last element, ramped in
//             over payload_ramp_steps control steps.
//   outer-loop corrections are ramped: a re-solved shape target is blended in over outer_period
//             control steps, and one whose blend tip path fails the continuity check is refused.
//   reported state: converged() (the path's end reached: within converged_position /
//             converged_rotation of the target and every observed node slower than
//             converged_speed), saturated(), predicted_shape(step) along the current path.
// Only the observation is used: target, node positions/velocities, the end-effector pose.
// No heap allocation in act() after the first call for a target; the inverse statics set-up of a
// new target runs inside that call.
//
// Length: the feed-forward, the feedback map, the stiffness estimate, the outer loop and the line
// tracking act on one executor state every control step (longer than the project's usual 600 lines
// for that reason).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>
#include <Eigen/Geometry>

#include "manisoft/control/executor.hpp"
#include "manisoft/rod/inverse_statics.hpp"
#include "manisoft/math/so3.hpp"

namespace manisoft::control {

template <typename Scalar>
struct ModelExecutorSettings {
  Scalar damping_gain = Scalar(35);        ///< kd, 1/s: node force -kd m v
  Scalar position_gain = Scalar(800);      ///< kp, 1/s^2: node force -kp m (x - x_desired), same mapping
  Scalar outer_gain = Scalar(0.1);         ///< K per outer update (0 disables the outer loop)
  int outer_period = 20;                   ///< control steps between outer (and estimate) updates
  int outer_delay = 60;                    ///< control steps after the ramp before the first outer update
  int ramp_steps = 250;                    ///< control steps of the shape ramp to a new target (minimum)
  int max_ramp_steps = 800;                ///< longest ramp
  Scalar ramp_max_speed = Scalar(0.006);   ///< m per control step: mean tip speed along the ramp's path
  Scalar ramp_max_node_step = std::numeric_limits<Scalar>::infinity();  ///< m per control step: planned peak speed of every node along the ramp (infinity: no bound)
  Scalar ramp_path_ratio = std::numeric_limits<Scalar>::infinity();  ///< a ramp segment whose tip path exceeds this x its straight distance gets a via shape (infinity: one blend)
  int ramp_via_depth = 4;                  ///< halvings of a ramp segment by via shapes, at most (up to 2^depth segments)
  Scalar ramp_line_relief = Scalar(0.9);   ///< line vias (ramp_path_ratio): torque ratio above which a via's actuation is relieved
  Scalar ramp_cruise = Scalar(0);          ///< ramp timing: 0 smoothstep; in (0, 1) the cruise timing of track_line (lower peak speed for the same duration)
  Scalar outer_speed_gate = Scalar(0.15);  ///< m/s: integrate only while every observed node is slower
  Scalar outer_max_shift = Scalar(0.3);    ///< bound on |p_s - p*| (m) and |log(R_s R*^T)| (rad)
  Scalar stiffness_gain = Scalar(1);       ///< g of the stiffness-scale estimate (0: off)
  int estimate_delay = 20;                 ///< control steps after the ramp before estimating
  Scalar estimate_speed_gate = Scalar(1);  ///< m/s: estimate only while every observed node is slower
  Scalar min_stiffness_scale = Scalar(0.5);  ///< bounds of s_hat
  bool carry_saturation = true;            ///< a clamped element's excess goes to the next proximal one
  Scalar max_stiffness_scale = Scalar(2);
  Scalar twist_gain = Scalar(20);          ///< N m/rad: twist couple -k phi_tip (s_k / L) on the tip twist error
  Scalar twist_damping = Scalar(0);        ///< N m s/rad: twist couple -c w_tip (s_k / L) from end-effector
                                           ///< pose differences (0: off)
  // ---- trajectory tracking (track_line)
  Scalar knot_spacing = Scalar(0.01);      ///< m of tip travel between knots of a path, at most
  Scalar knot_angle = Scalar(0.05);        ///< rad of tip rotation between knots, at most
  int max_knot_steps = 25;                 ///< control steps between knots, at most
  int max_knots = 120;                     ///< knots of one path (before subdivision)
  int max_subdivisions = 3;                ///< halvings of a knot interval that fails the continuity check
  Scalar path_ratio_limit = Scalar(1.5);   ///< knot-to-knot tip path / straight distance, at most
  bool velocity_feedforward = true;        ///< track v - v* (desired node velocities) on paths
  // ---- payload and reported state
  int payload_ramp_steps = 40;             ///< control steps to ramp a payload change in
  Scalar converged_position = Scalar(0.005);  ///< m
  Scalar converged_rotation = Scalar(0.05);   ///< rad
  Scalar converged_speed = Scalar(0.05);      ///< m/s, every observed node

  /// The defaults with a smooth shape ramp (transient limits: no node faster than 1.5 m/s, no
  /// tip path longer than 1.5 x the straight distance): the planned peak node speed
  /// bounded by `max_node_step` (m per control step), via shapes where a blend's tip path exceeds
  /// 1.2 x its straight distance, the cruise timing (peak 1.33 x the mean speed), and ramps up to
  /// `max_ramp` control steps long. Slower than the default ramp (docs/executors.md).
  static ModelExecutorSettings smooth_ramp(Scalar max_node_step, int max_ramp) {
    ModelExecutorSettings s;
    s.ramp_max_node_step = max_node_step;
    s.ramp_path_ratio = Scalar(1.2);
    s.ramp_cruise = Scalar(0.5);
    s.max_ramp_steps = std::max(max_ramp, s.ramp_steps);
    return s;
  }
};

/// What track_line() planned (or why it refused).
template <typename Scalar>
struct PathReport {
  bool accepted = false;
  const char* reason = "";       ///< why a path was refused ("" when accepted)
  int steps = 0;                 ///< control steps of the path
  int knots = 0;                 ///< knots after subdivision (the start included)
  int subdivisions = 0;          ///< knot intervals halved by the continuity check
  Scalar straight = 0;           ///< |p_goal - p_start|, m
  Scalar tip_path = 0;           ///< sampled tip path of the planned shape sequence, m
  Scalar ratio = 1;              ///< tip_path / straight (1 for paths shorter than 1 mm)
  Scalar max_torque_ratio = 0;   ///< largest |tau_ff| / limit over the knots
  Scalar max_node_step = 0;      ///< planned peak node speed, m per control step (after any stretch)
};

template <typename ScalarType>
class ModelExecutor {
 public:
  using Scalar = ScalarType;
  using Array3 = Eigen::Matrix<Scalar, Eigen::Dynamic, 3>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  using Pose = math::Pose<Scalar>;
  using Coefficients = typename rod::InverseStatics<Scalar>::Coefficients;

  ModelExecutor(rod::ArmModel<Scalar> model, rod::ActuationLimits<Scalar> limits, ModelExecutorSettings<Scalar> settings = {},
                rod::InverseStaticsSettings<Scalar> statics = {})
      : statics_(std::move(model), statics, limits), settings_(settings) {
    manisoft::detail::require_non_negative("ModelExecutor damping_gain", settings_.damping_gain);
    manisoft::detail::require_non_negative("ModelExecutor outer_gain", settings_.outer_gain);
    manisoft::detail::require_non_negative("ModelExecutor position_gain", settings_.position_gain);
    if (settings_.ramp_steps < 0) manisoft::detail::fail("ModelExecutor ramp_steps = ", settings_.ramp_steps, " must be >= 0");
    if (settings_.max_ramp_steps < settings_.ramp_steps)
      manisoft::detail::fail("ModelExecutor max_ramp_steps = ", settings_.max_ramp_steps, " must be >= ramp_steps = ", settings_.ramp_steps);
    manisoft::detail::require_positive("ModelExecutor ramp_max_speed", settings_.ramp_max_speed);
    if (!(settings_.ramp_max_node_step > 0)) manisoft::detail::fail("ModelExecutor ramp_max_node_step = ", settings_.ramp_max_node_step, " must be > 0");
    if (!(settings_.ramp_cruise >= Scalar(0) && settings_.ramp_cruise < Scalar(1))) manisoft::detail::fail("ModelExecutor ramp_cruise = ", settings_.ramp_cruise, " must be in [0, 1)");
    if (!(settings_.ramp_path_ratio >= Scalar(1))) manisoft::detail::fail("ModelExecutor ramp_path_ratio = ", settings_.ramp_path_ratio, " must be >= 1");
    if (!(settings_.ramp_line_relief > Scalar(0) && settings_.ramp_line_relief <= Scalar(1))) manisoft::detail::fail("ModelExecutor ramp_line_relief = ", settings_.ramp_line_relief, " must be in (0, 1]");
    if (settings_.ramp_via_depth < 0 || settings_.ramp_via_depth > 4)
      manisoft::detail::fail("ModelExecutor ramp_via_depth = ", settings_.ramp_via_depth, " must be in [0, 4]");
    if (settings_.outer_period < 1) manisoft::detail::fail("ModelExecutor outer_period = ", settings_.outer_period, " must be >= 1");
    if (settings_.outer_delay < 0) manisoft::detail::fail("ModelExecutor outer_delay = ", settings_.outer_delay, " must be >= 0");
    manisoft::detail::require_positive("ModelExecutor outer_max_shift", settings_.outer_max_shift);
    manisoft::detail::require_non_negative("ModelExecutor stiffness_gain", settings_.stiffness_gain);
    manisoft::detail::require_non_negative("ModelExecutor twist_damping", settings_.twist_damping);
    manisoft::detail::require_non_negative("ModelExecutor twist_gain", settings_.twist_gain);
    if (settings_.estimate_delay < 0) manisoft::detail::fail("ModelExecutor estimate_delay = ", settings_.estimate_delay, " must be >= 0");
    if (!(settings_.min_stiffness_scale > 0) || !(settings_.max_stiffness_scale >= settings_.min_stiffness_scale) ||
        !std::isfinite(settings_.max_stiffness_scale))
      manisoft::detail::fail("ModelExecutor stiffness scale bounds [", settings_.min_stiffness_scale, ", ", settings_.max_stiffness_scale, "] are invalid");
    const int n = statics_.n_elements();
    positions_.setZero(n + 1, 3);
    velocities_.setZero(n + 1, 3);
    direction_.setZero(n + 1, 3);
    manisoft::detail::require_positive("ModelExecutor knot_spacing", settings_.knot_spacing);
    manisoft::detail::require_positive("ModelExecutor knot_angle", settings_.knot_angle);
    if (settings_.max_knot_steps < 1) manisoft::detail::fail("ModelExecutor max_knot_steps = ", settings_.max_knot_steps, " must be >= 1");
    if (settings_.max_knots < 1) manisoft::detail::fail("ModelExecutor max_knots = ", settings_.max_knots, " must be >= 1");
    if (settings_.max_subdivisions < 0 || settings_.max_subdivisions > 8)
      manisoft::detail::fail("ModelExecutor max_subdivisions = ", settings_.max_subdivisions, " must be in [0, 8]");
    if (!(settings_.path_ratio_limit >= Scalar(1))) manisoft::detail::fail("ModelExecutor path_ratio_limit = ", settings_.path_ratio_limit, " must be >= 1");
    if (settings_.payload_ramp_steps < 0) manisoft::detail::fail("ModelExecutor payload_ramp_steps = ", settings_.payload_ramp_steps, " must be >= 0");
    manisoft::detail::require_positive("ModelExecutor converged_position", settings_.converged_position);
    manisoft::detail::require_positive("ModelExecutor converged_rotation", settings_.converged_rotation);
    manisoft::detail::require_positive("ModelExecutor converged_speed", settings_.converged_speed);
    node_mass_ = statics_.model().rod.node_masses;
    node_mass_[n] += statics_.model().payload_mass;
    tip_node_mass_ = node_mass_[n];
    desired_velocity_.setZero(n + 1, 3);
    previous_desired_.setZero(n + 1, 3);
    knot_positions_.setZero(n + 1, 3);
    for (Array3& nodes : ramp_nodes_) nodes.setZero(n + 1, 3);
    knots_.reserve(static_cast<std::size_t>(settings_.max_knots) << settings_.max_subdivisions);
    knots_.push_back(Knot{Scalar(0), statics_.coefficients()});
  }

  /// Forgets the target; the arm is assumed straight at rest (the shape ramp starts there).
  void reset() {
    has_target_ = false;
    has_previous_ = false;
    steps_ = 0;
    tracking_ = false;
    outer_ramp_ = 0;
    payload_ = payload_from_ = payload_to_ = Scalar(0);
    payload_offset_.setZero();
    payload_step_ = payload_steps_ = 0;
    node_mass_[statics_.n_elements()] = tip_node_mass_;
    converged_ = saturated_ = estimate_frozen_ = false;
    statics_.set_model_estimates(Scalar(1), statics_.model().payload_mass);
    statics_.set_coefficients(rod::InverseStatics<Scalar>::Coefficients::Zero());
    adapt_count_ = 0;
  }

  void act(const Observation<Scalar>& o, Array3& action) {
    const int n = statics_.n_elements();
    validate_observation(o, n + 1);
    if (action.rows() != n) action.resize(n, 3);  // allocates only if the caller passed a wrong size
    if (!has_target_ || !same_pose(o.target, target_)) set_target(o.target);
    const Scalar control_dt = has_previous_ && o.time > previous_time_ ? o.time - previous_time_ : Scalar(0);
    advance_payload();
    advance_shape_target(o);
    update_desired_velocity(control_dt);
    interpolate(o);
    const Scalar twist_rate = tip_twist_rate(o);
    const Scalar max_speed = o.node_velocities.rowwise().norm().maxCoeff();
    const bool adapting = settings_.stiffness_gain > Scalar(0) && steps_ >= ramp_steps_ + settings_.estimate_delay &&
                          max_speed <= settings_.estimate_speed_gate;
    saturated_ = feedforward_plus_feedback(o, twist_rate, action);
    // A saturated actuator does not apply the torque the estimate assumes: no update then.
    if (adapting && !saturated_ && !estimate_frozen_) accumulate_estimate(o);
    ++steps_;
    converged_ = steps_ >= ramp_steps_ && max_speed <= settings_.converged_speed &&
                 (o.end_effector.translation - target_.translation).norm() <= settings_.converged_position &&
                 math::so3::log(Matrix3(target_.rotation * o.end_effector.rotation.transpose())).norm() <= settings_.converged_rotation;
  }

  /// Follows the straight SE(3) line from the current shape target's tip pose to `goal` over
  /// `steps` control steps (quintic timing), without a ramp: the knots' inverse statics are
  /// warm-started along the path and checked for continuity (see the header comment). `steps`
  /// may be 0 only for a path of length zero (a point target: hold the current shape). A refused
  /// path (report.accepted false, with the reason) leaves the executor as it was. Allocates
  /// nothing (the knot table is reserved at construction; on a copy, at its first path).
  ///
  /// `max_node_step` (m per control step; infinity: no bound) bounds the planned speed of every
  /// node: the knot shapes' largest node displacement over each knot interval, divided by the
  /// interval's control steps. A path planned faster is slowed (its steps stretched, reported in
  /// report.steps); the timing's shape is kept.
  ///
  /// `cruise` in [0, 1) picks the timing: 0 quintic (minimum jerk, peak speed 1.875 x the mean);
  /// above 0 a constant speed over that fraction of the steps, reached and left along cubic
  /// smoothstep speed ramps over the rest, half at each end (peak speed 2 / (1 + cruise) x the
  /// mean, acceleration continuous and zero at both ends): path_timing().
  PathReport<Scalar> track_line(const Pose& goal, int steps, Scalar max_node_step = std::numeric_limits<Scalar>::infinity(), Scalar cruise = Scalar(0)) {
    math::require_valid_pose(goal, "executor path goal");
    if (steps < 0) manisoft::detail::fail("executor: track_line steps = ", steps, " must be >= 0");
    if (!(max_node_step > Scalar(0))) manisoft::detail::fail("executor: track_line max_node_step = ", max_node_step, " must be > 0");
    if (!(cruise >= Scalar(0) && cruise < Scalar(1))) manisoft::detail::fail("executor: track_line cruise = ", cruise, " must be in [0, 1)");
    cruise_ = cruise;
    PathReport<Scalar> report;
    report.steps = steps;
    const Coefficients c0 = statics_.coefficients();
    const Pose p0 = statics_.desired_tip_pose();
    path_start_ = p0;
    path_goal_ = goal;
    path_rotation_ = math::so3::log(Matrix3(p0.rotation.transpose() * goal.rotation));
    report.straight = (goal.translation - p0.translation).norm();
    const Scalar angle = path_rotation_.norm();
    const bool zero_length = report.straight < Scalar(1e-9) && angle < Scalar(1e-9);
    if (steps == 0 && !zero_length) {
      report.reason = "a path of non-zero length needs steps >= 1";
      return report;
    }
    int k = 1;
    if (!zero_length) {
      const Scalar need = std::max({report.straight / settings_.knot_spacing, angle / settings_.knot_angle,
                                    Scalar(steps) / Scalar(settings_.max_knot_steps), Scalar(1)});
      k = std::min({static_cast<int>(std::ceil(need)), settings_.max_knots, std::max(steps, 1)});
    }
    knots_.clear();
    // (a copied executor's table lost its reserve: restored here, once)
    knots_.reserve(static_cast<std::size_t>(settings_.max_knots) << settings_.max_subdivisions);
    knots_.push_back(Knot{Scalar(0), c0});
    knot_positions_ = statics_.desired_state().positions;
    max_node_rate_ = 0;
    Vector3 tip_previous = p0.translation;
    bool ok = true;
    for (int i = 1; i <= k && ok; ++i) {
      const Scalar u0 = Scalar(i - 1) / Scalar(k), u1 = Scalar(i) / Scalar(k);
      ok = plan_interval(u0, u1, Scalar(steps), 0, tip_previous, report);
    }
    statics_.set_coefficients(c0);
    // Node speed bound: stretch the timing (knot times scale with the steps).
    Scalar node_rate = max_node_rate_;  // m per control step at `steps`
    if (ok && steps > 0 && node_rate > max_node_step) {
      const int stretched = static_cast<int>(std::ceil(Scalar(steps) * node_rate / max_node_step));
      const Scalar scale = Scalar(stretched) / Scalar(steps);
      for (Knot& knot : knots_) knot.t *= scale;
      node_rate /= scale;
      steps = stretched;
      report.steps = steps;
    }
    report.max_node_step = node_rate;
    if (!ok) {
      knots_.clear();
      knots_.push_back(Knot{Scalar(0), c0});
      report.knots = 0;
      return report;
    }
    report.accepted = true;
    report.knots = static_cast<int>(knots_.size());
    report.ratio = report.straight > Scalar(1e-3) ? report.tip_path / report.straight : Scalar(1);
    target_ = goal;
    shifted_ = goal;
    has_target_ = true;
    tracking_ = true;
    knot_cursor_ = 0;
    path_steps_ = steps;
    ramp_steps_ = steps;
    steps_ = 0;
    outer_ramp_ = 0;
    error_sum_.setZero();
    error_count_ = 0;
    adapt_count_ = 0;
    last_path_ = report;
    return report;
  }

  /// Jumps to the end of the current path or shape ramp (and of a payload ramp) without running it: the shape
  /// target becomes the path's last knot. For planners that chain track_line() calls to check a
  /// whole sequence before running it (on a copy of the executor).
  void complete_path() {
    if (tracking_) {
      statics_.set_coefficients(knots_.back().c);
      knots_.front() = knots_.back();
      knots_.front().t = 0;
      knots_.resize(1);
      path_steps_ = 0;
      ramp_steps_ = 0;
      steps_ = 0;
    } else if (has_target_ && steps_ < ramp_steps_) {
      statics_.set_coefficients(ramp_end_);
      ramp_steps_ = 0;
      steps_ = 0;
    }
    if (payload_step_ < payload_steps_) {
      payload_step_ = payload_steps_;
      apply_payload(payload_to_);
    }
  }

  /// Tells the executor the end-effector holds an object of `mass` kg whose centre of mass is at
  /// `offset` in the end-effector frame (mass 0: nothing held). Ramped in over payload_ramp_steps.
  void set_payload(Scalar mass, const Vector3& offset = Vector3::Zero()) {
    if (!(mass >= 0) || !std::isfinite(mass)) manisoft::detail::fail("executor: payload mass = ", mass, " kg is invalid: it must be finite and >= 0");
    if (!offset.allFinite()) manisoft::detail::fail("executor: payload offset (", offset.transpose(), ") is not finite");
    payload_from_ = payload_;
    payload_to_ = mass;
    if (mass > 0) payload_offset_ = offset;
    payload_step_ = 0;
    payload_steps_ = settings_.payload_ramp_steps;
    if (payload_steps_ == 0) apply_payload(mass);
  }
  Scalar payload() const { return payload_; }

  /// Freezes (true) or resumes (false) the stiffness estimate, keeping its current value. The
  /// estimate assumes the arm carries nothing but its model and payload: a planner that knows its
  /// tool presses on something (fingers around an object, a held object set on its support)
  /// freezes it meanwhile, or that contact's deflection is read as a stiffness error and the
  /// feed-forward changes under the contact (it can drive a twist chatter at the tip).
  /// A partial averaging period is dropped either way.
  void freeze_estimate(bool frozen) {
    if (frozen != estimate_frozen_) adapt_count_ = 0;
    estimate_frozen_ = frozen;
  }
  bool estimate_frozen() const { return estimate_frozen_; }

  /// Converged: the current path's (or ramp's) end reached, the end-effector within
  /// converged_position / converged_rotation of the target and every observed node slower than
  /// converged_speed (as of the last act()).
  bool converged() const { return converged_; }
  /// Whether an actuated element hit its limit in the last act().
  bool saturated() const { return saturated_; }
  /// Whether the current path (or ramp) has been run to its end.
  bool path_done() const { return steps_ >= ramp_steps_; }
  /// Control steps since the current path (or ramp) started.
  long path_step() const { return steps_; }
  /// Whether the current target is followed along a line (track_line), not a shape ramp (set_target).
  bool tracking() const { return tracking_; }
  const PathReport<Scalar>& last_path() const { return last_path_; }
  /// The desired shape ((n + 1) x 3 node positions) `step` control steps into the current path
  /// (clamped to its end); for planners that check the whole arm against obstacles. Changes
  /// nothing; does not allocate.
  void predicted_shape(long step, Array3& positions) {
    positions.resize(statics_.n_elements() + 1, 3);
    statics_.shape_positions(coefficients_at(step), positions);
  }

  /// Sets up a new target (inverse statics from cold starts); act() calls it when the target changes.
  rod::InverseStaticsResult<Scalar> set_target(const Pose& target) {
    if (!target.is_finite()) manisoft::detail::fail("executor: target pose refused, it is not finite (translation = ", target.translation.transpose(), ")");
    target_ = target;
    shifted_ = target;
    has_target_ = true;
    steps_ = 0;
    error_sum_.setZero();
    error_count_ = 0;
    adapt_count_ = 0;
    ramp_start_ = statics_.coefficients();
    last_result_ = statics_.solve_cold(target);
    ramp_end_ = statics_.coefficients();
    ramp_knots_[0] = ramp_start_;
    ramp_knot_count_ = 1;
    if (std::isfinite(settings_.ramp_path_ratio) && last_result_.within_limits && settings_.ramp_steps > 0) {
      Scalar path = 0;
      add_ramp_segment(ramp_start_, ramp_end_, 0, path);
      try_line_vias(path);
      statics_.set_coefficients(ramp_end_);
    } else {
      ramp_knots_[ramp_knot_count_++] = ramp_end_;
    }
    // the knots' blend parameters, proportional to the segments' node paths (so no segment is
    // crossed faster than the others)
    ramp_knot_s_[0] = 0;
    for (std::size_t i = 1; i < static_cast<std::size_t>(ramp_knot_count_); ++i)
      ramp_knot_s_[i] = ramp_knot_s_[i - 1] + (ramp_knot_count_ == 2 ? Scalar(1) : blend_node_path(ramp_knots_[i - 1], ramp_knots_[i]));
    const auto last = static_cast<std::size_t>(ramp_knot_count_ - 1);
    const Scalar total = ramp_knot_s_[last];
    for (std::size_t i = 1; i <= last; ++i) ramp_knot_s_[i] = total > Scalar(0) ? ramp_knot_s_[i] / total : Scalar(i) / Scalar(last);
    // Ramp length: at least ramp_steps, longer when the blend's tip path (sampled) is long, so
    // that the mean tip speed along it stays below ramp_max_speed, and when a node's planned
    // peak speed (largest node displacement between samples of the timed blend) would exceed
    // ramp_max_node_step.
    ramp_path_ = 0;
    Scalar node_rate = 0;  // largest node displacement per unit of ramp time
    const bool bound_nodes = std::isfinite(settings_.ramp_max_node_step);
    if (settings_.ramp_steps > 0) {
      Vector3 previous = statics_.tip_pose(ramp_start_).translation;
      if (bound_nodes) statics_.shape_positions(ramp_start_, ramp_nodes_[0]);
      const int samples = ramp_samples * std::max(1, (ramp_knot_count_ - 1) / 2);
      for (int i = 1; i <= samples; ++i) {
        const Scalar x = Scalar(i) / Scalar(samples);
        const Coefficients c = ramp_coefficients(ramp_timing(x));
        const Vector3 p = statics_.tip_pose(c).translation;
        ramp_path_ += (p - previous).norm();
        previous = p;
        if (bound_nodes) {
          Array3& now = ramp_nodes_[i % 2];
          statics_.shape_positions(c, now);
          node_rate = std::max(node_rate, Scalar(samples) * (now - ramp_nodes_[(i + 1) % 2]).rowwise().norm().maxCoeff());
        }
      }
    }
    const Scalar needed = std::max(ramp_path_ / settings_.ramp_max_speed, bound_nodes ? node_rate / settings_.ramp_max_node_step : Scalar(0));
    ramp_steps_ = settings_.ramp_steps == 0 ? 0 : std::clamp(static_cast<int>(std::ceil(needed)), settings_.ramp_steps, settings_.max_ramp_steps);
    statics_.set_coefficients(ramp_steps_ > 0 ? ramp_start_ : ramp_end_);
    tracking_ = false;
    outer_ramp_ = 0;
    return last_result_;
  }

  const rod::InverseStatics<Scalar>& statics() const { return statics_; }
  const rod::InverseStaticsResult<Scalar>& last_statics_result() const { return last_result_; }
  const ModelExecutorSettings<Scalar>& settings() const { return settings_; }
  const Pose& shape_target() const { return shifted_; }
  /// Control steps of the current target's shape ramp and the tip path length along it (m).
  int ramp_length() const { return ramp_steps_; }
  Scalar ramp_path() const { return ramp_path_; }
  /// Outer-loop re-solves refused by the continuity check (since construction).
  long refused_corrections() const { return refused_corrections_; }
  /// The stiffness scale the feed-forward currently assumes (1 = the model's).
  Scalar stiffness_estimate() const { return statics_.stiffness_scale(); }

 private:
  /// Stage 1: the shape target of this step: along the ramp (every intermediate shape an exact
  /// equilibrium of the model), then the outer loop's corrections.
  void advance_shape_target(const Observation<Scalar>& o) {
    if (tracking_) {
      if (steps_ < path_steps_) {
        statics_.set_coefficients(coefficients_at(steps_ + 1));
      } else if (outer_ramp_ > 0) {
        advance_outer_ramp();
      } else {
        if (steps_ == path_steps_) statics_.set_coefficients(knots_.back().c);
        outer_loop(o);
      }
      return;
    }
    if (outer_ramp_ > 0) {
      advance_outer_ramp();
      return;
    }
    if (steps_ < ramp_steps_) {
      const Scalar x = Scalar(steps_ + 1) / Scalar(ramp_steps_);
      statics_.set_coefficients(ramp_coefficients(ramp_timing(x)));
    } else {
      outer_loop(o);
    }
  }

  /// Stage 2: twist rate at the tip from successive end-effector poses (lab angular velocity . d3).
  Scalar tip_twist_rate(const Observation<Scalar>& o) {
    Scalar rate = 0;
    if (has_previous_ && o.time > previous_time_) {
      const Vector3 w = math::so3::log(Matrix3(o.end_effector.rotation * previous_rotation_.transpose())) / (o.time - previous_time_);
      if (w.allFinite()) rate = w.dot(o.end_effector.rotation.col(2));
    }
    previous_rotation_ = o.end_effector.rotation;
    previous_time_ = o.time;
    has_previous_ = true;
    return rate;
  }

  /// Stage 3: feed-forward plus the node feedback turned into element couples through the lever
  /// arms of the nodes beyond each element, the twist couple, clamped with the saturation carry.
  /// Returns whether an actuated element saturated.
  bool feedforward_plus_feedback(const Observation<Scalar>& o, Scalar twist_rate, Array3& action) const {
    const int n = statics_.n_elements();
    const Array3& ff = statics_.feedforward();
    const rod::RodState<Scalar>& desired = statics_.desired_state();
    const auto& limits = statics_.limits();
    Vector3 distal = Vector3::Zero();
    Vector3 excess = Vector3::Zero();  // clamped-off torque carried to the next proximal element
    Scalar tip_twist = 0;
    bool saturated = false;
    for (int k = n - 1; k >= 0; --k) {
      distal -= node_mass_[k + 1] * (settings_.damping_gain * (velocities_.row(k + 1) - desired_velocity_.row(k + 1)).transpose() +
                                     settings_.position_gain * (positions_.row(k + 1) - desired.positions.row(k + 1)).transpose());
      const Vector3 lever = (positions_.row(k + 1) - positions_.row(k)).transpose();
      // Material frame of element k estimated from the desired one, turned by the smallest
      // rotation that takes the desired element tangent onto the observed one.
      const Vector3 desired_lever = (desired.positions.row(k + 1) - desired.positions.row(k)).transpose();
      const Matrix3 turn = Eigen::Quaternion<Scalar>::FromTwoVectors(desired_lever, lever).toRotationMatrix();
      const Matrix3 frame = desired.director(k) * turn.transpose();  // lab -> estimated material
      if (k == n - 1) {
        // Twist of the observed tip frame about the tip tangent relative to the estimated one.
        const Vector3 d = math::so3::log(Matrix3(o.end_effector.rotation * frame));
        tip_twist = d.allFinite() ? d.dot(lever.normalized()) : Scalar(0);
      }
      Vector3 couple = frame * lever.cross(distal);
      // A held object's couple about the tip (its weight at the offset), cancelled on the last element.
      if (k == n - 1 && payload_ > Scalar(0))
        couple -= payload_ * payload_offset_.cross(Matrix3(desired.director(k)) * statics_.model().gravity);
      const Scalar share = (Scalar(k) + Scalar(0.5)) / Scalar(n);
      couple[2] -= share * (settings_.twist_gain * tip_twist + settings_.twist_damping * twist_rate);
      for (int i = 0; i < 3; ++i) {
        const Scalar lim = limits.limit(i);
        const Scalar a = ff(k, i) + couple[i] + (settings_.carry_saturation ? excess[i] : Scalar(0));
        if (k > 0 && std::abs(a) > lim) saturated = true;
        action(k, i) = std::clamp(a, -lim, lim);
        excess[i] = a - action(k, i);
      }
    }
    action.row(0).setZero();
    return saturated;
  }

  static bool same_pose(const Pose& a, const Pose& b) {
    return a.translation == b.translation && a.rotation == b.rotation;
  }

  /// Node positions and velocities of every node: the observed position errors (observed minus
  /// desired) and velocities interpolated linearly between observed nodes (held constant past
  /// the first/last observed node); positions = desired + interpolated error.
  void interpolate(const Observation<Scalar>& o) {
    const int n_nodes = statics_.n_elements() + 1;
    const rod::RodState<Scalar>& desired = statics_.desired_state();
    const auto m = o.node_indices.size();
    Eigen::Index seg = 0;
    for (int j = 0; j < n_nodes; ++j) {
      while (seg + 2 < m && o.node_indices[seg + 1] < j) ++seg;
      const int a = o.node_indices[seg], b = o.node_indices[seg + 1];
      const Scalar w = std::clamp(Scalar(j - a) / Scalar(b - a), Scalar(0), Scalar(1));
      const Eigen::Matrix<Scalar, 1, 3> ea = o.node_positions.row(seg) - desired.positions.row(a);
      const Eigen::Matrix<Scalar, 1, 3> eb = o.node_positions.row(seg + 1) - desired.positions.row(b);
      positions_.row(j) = desired.positions.row(j) + (Scalar(1) - w) * ea + w * eb;
      velocities_.row(j) = (Scalar(1) - w) * o.node_velocities.row(seg) + w * o.node_velocities.row(seg + 1);
    }
  }

  /// Stiffness-scale estimate from the observed shape: with the arm quasi-static, the deviation
  /// of the observed nodes (and the tip rotation) from the desired shape is regressed on the
  /// shape change of a relative curvature scaling (rod::InverseStatics::curvature_scale_direction);
  /// a stiffer arm (s > s_hat) bends less (beta < 0), so s_hat <- s_hat (1 - gain beta).
  void accumulate_estimate(const Observation<Scalar>& o) {
    if (adapt_count_ == 0) {
      statics_.curvature_scale_direction(direction_, direction_tip_);
      adapt_num_ = adapt_den_ = 0;
    }
    const rod::RodState<Scalar>& desired = statics_.desired_state();
    Scalar num = 0, den = 0;
    for (Eigen::Index i = 0; i < o.node_indices.size(); ++i) {
      const int j = o.node_indices[i];
      if (j == 0) continue;
      const Vector3 u = direction_.row(j).transpose();
      const Vector3 d = (o.node_positions.row(i) - desired.positions.row(j)).transpose();
      num += u.dot(d);
      den += u.dot(u);
    }
    const Scalar w = statics_.settings().rotation_weight;
    const Matrix3 desired_tip = desired.tip_pose().rotation;
    const Vector3 dr = math::so3::log(Matrix3(o.end_effector.rotation * desired_tip.transpose()));
    num += w * w * direction_tip_.dot(dr);
    den += w * w * direction_tip_.squaredNorm();
    if (!std::isfinite(num) || !std::isfinite(den)) return;
    adapt_num_ += num;
    adapt_den_ += den;
    if (++adapt_count_ < settings_.outer_period) return;
    adapt_count_ = 0;
    if (!(adapt_den_ > Scalar(1e-12))) return;
    const Scalar beta = std::clamp(adapt_num_ / adapt_den_, Scalar(-0.2), Scalar(0.2));
    const Scalar s = std::clamp(statics_.stiffness_scale() * (Scalar(1) - settings_.stiffness_gain * beta), settings_.min_stiffness_scale,
                                settings_.max_stiffness_scale);
    statics_.set_model_estimates(s, statics_.payload_estimate());
  }

  void outer_loop(const Observation<Scalar>& o) {
    if (settings_.outer_gain == Scalar(0) || steps_ < ramp_steps_ + settings_.outer_delay) return;
    Eigen::Matrix<Scalar, 6, 1> e;
    e.template head<3>() = target_.translation - o.end_effector.translation;
    e.template tail<3>() = math::so3::log(target_.rotation * o.end_effector.rotation.transpose());
    if (!e.allFinite()) return;
    // Integrate only while the arm is quasi-static: during transients the pose error is not the
    // static error the shape shift should remove, and integrating it winds up the loop.
    if (o.node_velocities.rowwise().norm().maxCoeff() > settings_.outer_speed_gate) return;
    error_sum_ += e;
    ++error_count_;
    if (error_count_ < settings_.outer_period) return;
    const Eigen::Matrix<Scalar, 6, 1> mean = error_sum_ / Scalar(error_count_);
    error_sum_.setZero();
    error_count_ = 0;
    const Scalar k = settings_.outer_gain;
    Pose next = shifted_;
    next.translation += k * mean.template head<3>();
    next.rotation = math::so3::exp(Vector3(k * mean.template tail<3>())) * shifted_.rotation;
    // Bound the shift away from the true target.
    Vector3 dp = next.translation - target_.translation;
    if (dp.norm() > settings_.outer_max_shift) next.translation = target_.translation + dp * (settings_.outer_max_shift / dp.norm());
    Vector3 dr = math::so3::log(next.rotation * target_.rotation.transpose());
    if (dr.norm() > settings_.outer_max_shift) next.rotation = math::so3::exp(Vector3(dr * (settings_.outer_max_shift / dr.norm()))) * target_.rotation;
    const Coefficients previous = statics_.coefficients();
    const Vector3 tip_before = statics_.desired_tip_pose().translation;
    const rod::InverseStaticsResult<Scalar> r = statics_.solve(next);
    const Coefficients solved = statics_.coefficients();
    statics_.set_coefficients(previous);
    if (!r.converged) return;
    // Continuity: a re-solve that lands on a distant shape branch is refused; otherwise it is
    // blended in over outer_period steps, never applied in one.
    const Scalar straight = (next.translation - tip_before).norm();
    if (blend_tip_path(previous, solved) > settings_.path_ratio_limit * straight + Scalar(1e-3)) {
      ++refused_corrections_;
      return;
    }
    shifted_ = next;
    outer_from_ = previous;
    outer_to_ = solved;
    outer_ramp_ = settings_.outer_period;
    outer_ramp_step_ = 0;
  }

  void advance_outer_ramp() {
    ++outer_ramp_step_;
    const Scalar x = Scalar(outer_ramp_step_) / Scalar(outer_ramp_);
    statics_.set_coefficients(outer_from_ + x * (outer_to_ - outer_from_));
    if (outer_ramp_step_ >= outer_ramp_) outer_ramp_ = 0;
  }

  /// Sampled tip path of the linear coefficient blend a -> b (m); uses the solver's buffers.
  Scalar blend_tip_path(const Coefficients& a, const Coefficients& b, int samples = 4) {
    Vector3 previous = statics_.tip_pose(a).translation;
    Scalar path = 0;
    for (int i = 1; i <= samples; ++i) {
      const Vector3 p = statics_.tip_pose(Coefficients(a + (Scalar(i) / Scalar(samples)) * (b - a))).translation;
      path += (p - previous).norm();
      previous = p;
    }
    return path;
  }

  /// The path's pose at path parameter u in [0, 1] (before timing).
  Pose path_pose(Scalar u) const {
    Pose p;
    p.translation = path_start_.translation + u * (path_goal_.translation - path_start_.translation);
    p.rotation = path_start_.rotation * math::so3::exp(Vector3(u * path_rotation_));
    return p;
  }

  static Scalar quintic(Scalar x) { return x * x * x * (Scalar(10) + x * (Scalar(-15) + Scalar(6) * x)); }

 public:
  /// Path parameter (0..1) at time fraction x of a path with cruise fraction `cruise` (track_line):
  /// quintic for 0; else speed V = 1 / (1 - a), a = (1 - cruise) / 2, reached over [0, a] along
  /// V smoothstep(x / a) and left symmetrically over [1 - a, 1].
  static Scalar path_timing(Scalar x, Scalar cruise) {
    if (!(cruise > Scalar(0))) return quintic(x);
    const Scalar a = Scalar(0.5) * (Scalar(1) - cruise), v = Scalar(1) / (Scalar(1) - a);
    const auto ramp = [&](Scalar t) { return v * a * t * t * t * (Scalar(1) - Scalar(0.5) * t); };  // V a (t^3 - t^4 / 2)
    if (x <= Scalar(0)) return Scalar(0);
    if (x >= Scalar(1)) return Scalar(1);
    if (x < a) return ramp(x / a);
    if (x > Scalar(1) - a) return Scalar(1) - ramp((Scalar(1) - x) / a);
    return Scalar(0.5) * v * a + v * (x - a);
  }

  /// Peak speed of path_timing() over its mean speed (distance / duration): 1.875 quintic;
  /// 2 / (1 + cruise) with a cruise. A planner times a line of given peak speed with it.
  static Scalar peak_speed_ratio(Scalar cruise) { return cruise > Scalar(0) ? Scalar(2) / (Scalar(1) + cruise) : Scalar(1.875); }
  /// Peak acceleration of path_timing() in units of distance / duration^2: 6 / (1 - cruise^2)
  /// with a cruise (smoothstep speed ramps over (1 - cruise) / 2 of the duration at each end);
  /// 5.7735 (10 / sqrt(3)) quintic.
  static Scalar peak_acceleration_ratio(Scalar cruise) { return cruise > Scalar(0) ? Scalar(6) / (Scalar(1) - cruise * cruise) : Scalar(5.7735); }

 private:

  /// Plans the knots of time fraction (u0, u1] of the current path (the knot at u0 is the last
  /// one in knots_); subdivides when the knot fails to converge within the limits or its blend
  /// fails the continuity check. Returns false when the path must be refused.
  bool plan_interval(Scalar u0, Scalar u1, Scalar steps, int depth, Vector3& tip_previous, PathReport<Scalar>& report) {
    const Coefficients from = knots_.back().c;
    const Pose pose = path_pose(path_timing(u1, cruise_));
    // The smallest shape change that meets the knot (continuity); the full solver only if that fails.
    rod::InverseStaticsResult<Scalar> r = statics_.solve_near(pose, from);
    if (!r.within_limits) r = statics_.solve_from(pose, from);
    const Coefficients to = statics_.coefficients();
    bool good = r.within_limits;
    Scalar blend_path = 0;
    const Scalar straight = (pose.translation - tip_previous).norm();
    if (good) {
      blend_path = blend_tip_path(from, to);
      good = blend_path <= settings_.path_ratio_limit * straight + Scalar(1e-3);
    }
    if (!good) {
      if (depth >= settings_.max_subdivisions) {
        report.reason = r.within_limits ? "shape branch jump: knot blend tip path exceeds path_ratio_limit x straight distance"
                                        : "a knot of the path has no converged inverse statics solution within the actuation limits";
        return false;
      }
      ++report.subdivisions;
      const Scalar mid = Scalar(0.5) * (u0 + u1);
      return plan_interval(u0, mid, steps, depth + 1, tip_previous, report) && plan_interval(mid, u1, steps, depth + 1, tip_previous, report);
    }
    if (knots_.size() == knots_.capacity()) {
      report.reason = "knot table full";
      return false;
    }
    knots_.push_back(Knot{u1 * steps, to});
    const Array3& x = statics_.desired_state().positions;
    const Scalar interval = (u1 - u0) * steps;
    if (interval > Scalar(0)) max_node_rate_ = std::max(max_node_rate_, (x - knot_positions_).rowwise().norm().maxCoeff() / interval);
    knot_positions_ = x;
    report.tip_path += blend_path;
    report.max_torque_ratio = std::max(report.max_torque_ratio, r.max_torque_ratio);
    tip_previous = pose.translation;
    return true;
  }

  /// Appends the ramp's knots from shape a (the last knot) to shape b. A blend whose tip path is
  /// longer than ramp_path_ratio x the straight distance of its ends gets a via shape: the
  /// blend's midpoint shape, its tip moved to the straight line's midpoint (or 0.8, 0.6, 0.45,
  /// 0.3, 0.15 of the way there) and re-solved near it (solve_near, else solve_from), kept when within the
  /// limits and the two blends through it are shorter; each half is checked again, at most
  /// ramp_via_depth halvings deep. Adds the tip path of each blend it appends to `ramp_path`.
  void add_ramp_segment(const Coefficients& a, const Coefficients& b, int depth, Scalar& ramp_path) {
    const Scalar path = blend_tip_path(a, b, 8);
    if (depth < settings_.ramp_via_depth) {
      const Vector3 pa = statics_.tip_pose(a).translation, pb = statics_.tip_pose(b).translation;
      if (path > settings_.ramp_path_ratio * (pb - pa).norm() + Scalar(1e-3)) {
        const Coefficients mid = Scalar(0.5) * (a + b);
        const Pose blend_mid = statics_.tip_pose(mid);
        for (const Scalar pull : {Scalar(1), Scalar(0.8), Scalar(0.6), Scalar(0.45), Scalar(0.3), Scalar(0.15)}) {
          const Pose via{blend_mid.rotation, blend_mid.translation + pull * (Scalar(0.5) * (pa + pb) - blend_mid.translation)};
          auto r = statics_.solve_near(via, mid, 20);
          if (!r.within_limits) r = statics_.solve_from(via, mid);
          if (!r.within_limits) continue;
          const Coefficients v = statics_.coefficients();
          if (blend_tip_path(a, v, 8) + blend_tip_path(v, b, 8) < Scalar(0.98) * path) {
            add_ramp_segment(a, v, depth + 1, ramp_path);
            add_ramp_segment(v, b, depth + 1, ramp_path);
            return;
          }
        }
      }
    }
    ramp_knots_[static_cast<std::size_t>(ramp_knot_count_++)] = b;
    ramp_path += path;
  }

  /// When the halving vias leave the ramp's tip path longer than ramp_path_ratio x the straight
  /// distance (a large rotation about the tool axis curls the arm out of its plane, and the
  /// pose-solved vias wander with it), the ramp runs instead through max_ramp_knots - 2 line
  /// vias: shapes whose tips lie evenly spaced on the straight line, each the one before moved by
  /// an even share of what remains of the coefficient change to the end shape and put on the line
  /// with the tip rotation left free (InverseStatics::solve_position_near), its actuation relieved
  /// below ramp_line_relief of the limits (a relieved via's drift is so spread over the vias
  /// after it, not left to the last blend). Kept when every via converged within the limits and
  /// the ramp's tip path got shorter.
  /// `path`: the tip path of the ramp's blends (add_ramp_segment's sum).
  void try_line_vias(Scalar path) {
    const Vector3 pa = statics_.tip_pose(ramp_start_).translation, pb = statics_.tip_pose(ramp_end_).translation;
    if (!(path > settings_.ramp_path_ratio * (pb - pa).norm() + Scalar(1e-3))) return;
    constexpr int vias = max_ramp_knots - 2;
    line_knots_[0] = ramp_start_;
    Scalar line_path = 0;
    for (std::size_t i = 1; i <= static_cast<std::size_t>(vias); ++i) {
      const Vector3 on_line = pa + (Scalar(i) / Scalar(vias + 1)) * (pb - pa);
      const Coefficients start = line_knots_[i - 1] + (ramp_end_ - line_knots_[i - 1]) / Scalar(vias + 2 - static_cast<int>(i));
      const auto r = statics_.solve_position_near(on_line, start, settings_.ramp_line_relief, line_relief_iterations);
      if (!r.within_limits) return;
      line_knots_[i] = statics_.coefficients();
      line_path += blend_tip_path(line_knots_[i - 1], line_knots_[i], 4);
    }
    line_knots_[vias + 1] = ramp_end_;
    line_path += blend_tip_path(line_knots_[vias], ramp_end_, 4);
    if (!(line_path < path)) return;
    ramp_knots_ = line_knots_;
    ramp_knot_count_ = max_ramp_knots;
  }

  /// The largest node displacement along the blend from shape a to b, summed over 4 samples.
  Scalar blend_node_path(const Coefficients& a, const Coefficients& b) {
    constexpr int samples = 4;
    statics_.shape_positions(a, ramp_nodes_[0]);
    Scalar path = 0;
    for (int i = 1; i <= samples; ++i) {
      statics_.shape_positions(Coefficients(a + (Scalar(i) / Scalar(samples)) * (b - a)), ramp_nodes_[static_cast<std::size_t>(i % 2)]);
      path += (ramp_nodes_[1] - ramp_nodes_[0]).rowwise().norm().maxCoeff();
    }
    return path;
  }

  /// The ramp's blend parameter at time fraction x: smoothstep, or path_timing with ramp_cruise.
  Scalar ramp_timing(Scalar x) const {
    return settings_.ramp_cruise > Scalar(0) ? path_timing(x, settings_.ramp_cruise) : x * x * (Scalar(3) - Scalar(2) * x);
  }

  /// The ramp's shape at blend parameter s in [0, 1]: linear between its knots.
  Coefficients ramp_coefficients(Scalar s) const {
    if (ramp_knot_count_ <= 2) return ramp_start_ + s * (ramp_end_ - ramp_start_);
    std::size_t hi = 1;
    while (hi + 1 < static_cast<std::size_t>(ramp_knot_count_) && ramp_knot_s_[hi] < s) ++hi;
    const Scalar span = ramp_knot_s_[hi] - ramp_knot_s_[hi - 1];
    const Scalar w = span > Scalar(0) ? std::clamp((s - ramp_knot_s_[hi - 1]) / span, Scalar(0), Scalar(1)) : Scalar(1);
    return ramp_knots_[hi - 1] + w * (ramp_knots_[hi] - ramp_knots_[hi - 1]);
  }

  /// Curvature coefficients of the current path at control step `step` (linear between knots).
  Coefficients coefficients_at(long step) {
    if (!tracking_) return statics_.coefficients();
    const Scalar t = Scalar(std::clamp<long>(step, 0, path_steps_));
    const auto last = knots_.size() - 1;
    if (knot_cursor_ > last) knot_cursor_ = 0;
    while (knot_cursor_ > 0 && knots_[knot_cursor_].t > t) --knot_cursor_;
    while (knot_cursor_ + 1 < last && knots_[knot_cursor_ + 1].t < t) ++knot_cursor_;
    if (last == 0) return knots_[0].c;
    const Knot& a = knots_[knot_cursor_];
    const Knot& b = knots_[knot_cursor_ + 1];
    const Scalar span = b.t - a.t;
    const Scalar w = span > Scalar(0) ? std::clamp((t - a.t) / span, Scalar(0), Scalar(1)) : Scalar(1);
    return a.c + w * (b.c - a.c);
  }

  /// Desired node velocities: the finite difference of the desired shape between control steps
  /// while a path is tracked (zero otherwise).
  void update_desired_velocity(Scalar control_dt) {
    const rod::RodState<Scalar>& desired = statics_.desired_state();
    if (tracking_ && settings_.velocity_feedforward && control_dt > Scalar(0) && steps_ > 0 && steps_ <= path_steps_) {
      desired_velocity_ = (desired.positions - previous_desired_) / control_dt;
    } else {
      desired_velocity_.setZero();
    }
    previous_desired_ = desired.positions;
  }

  void advance_payload() {
    if (payload_step_ >= payload_steps_) return;
    ++payload_step_;
    const Scalar x = Scalar(payload_step_) / Scalar(payload_steps_);
    apply_payload(payload_from_ + x * (payload_to_ - payload_from_));
  }

  void apply_payload(Scalar mass) {
    payload_ = mass;
    statics_.set_model_estimates(statics_.stiffness_scale(), statics_.model().payload_mass + mass);
    node_mass_[statics_.n_elements()] = tip_node_mass_ + mass;
  }

  rod::InverseStatics<Scalar> statics_;
  ModelExecutorSettings<Scalar> settings_;
  rod::InverseStaticsResult<Scalar> last_result_;
  Pose target_, shifted_;
  typename rod::InverseStatics<Scalar>::Coefficients ramp_start_ = rod::InverseStatics<Scalar>::Coefficients::Zero();
  typename rod::InverseStatics<Scalar>::Coefficients ramp_end_ = rod::InverseStatics<Scalar>::Coefficients::Zero();
  bool has_target_ = false;
  static constexpr int ramp_samples = 24;
  int ramp_steps_ = 0;
  Scalar ramp_path_ = 0;
  std::array<Array3, 2> ramp_nodes_;  ///< node positions of successive ramp samples (set_target)
  static constexpr int line_relief_iterations = 30;  // try_line_vias: relief steps per via, at most
  static constexpr int max_ramp_knots = 17;  // 2^ramp_via_depth + 1, depth at most 4
  std::array<Coefficients, max_ramp_knots> ramp_knots_{};  // the ramp's shapes (start, vias, end)
  std::array<Scalar, max_ramp_knots> ramp_knot_s_{};       // their blend parameters in [0, 1]
  std::array<Coefficients, max_ramp_knots> line_knots_{};  // try_line_vias' candidate ramp
  int ramp_knot_count_ = 2;
  long steps_ = 0;
  Array3 positions_, velocities_;
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> node_mass_;
  struct Knot {
    Scalar t;  ///< control steps from the path's start (fractional after subdivision)
    Coefficients c;
  };
  std::vector<Knot> knots_;
  Array3 knot_positions_;
  Scalar max_node_rate_ = 0;
  std::size_t knot_cursor_ = 0;
  bool tracking_ = false;
  long path_steps_ = 0;
  Pose path_start_, path_goal_;
  Vector3 path_rotation_ = Vector3::Zero();
  Scalar cruise_ = 0;  ///< the current path's cruise fraction (track_line)
  PathReport<Scalar> last_path_;
  Array3 desired_velocity_, previous_desired_;
  Coefficients outer_from_ = Coefficients::Zero(), outer_to_ = Coefficients::Zero();
  int outer_ramp_ = 0, outer_ramp_step_ = 0;
  long refused_corrections_ = 0;
  Scalar payload_ = 0, payload_from_ = 0, payload_to_ = 0;
  Vector3 payload_offset_ = Vector3::Zero();
  int payload_step_ = 0, payload_steps_ = 0;
  Scalar tip_node_mass_ = 0;
  bool converged_ = false, saturated_ = false, estimate_frozen_ = false;
  Eigen::Matrix<Scalar, 6, 1> error_sum_ = Eigen::Matrix<Scalar, 6, 1>::Zero();
  int error_count_ = 0;
  Matrix3 previous_rotation_ = Matrix3::Identity();
  Scalar previous_time_ = 0;
  bool has_previous_ = false;
  Array3 direction_;
  Vector3 direction_tip_ = Vector3::Zero();
  int adapt_count_ = 0;
  Scalar adapt_num_ = 0, adapt_den_ = 0;
};

}  // namespace manisoft::control
