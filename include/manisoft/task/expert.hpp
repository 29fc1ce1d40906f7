// The expert of the ManiSoft tasks (paper section 3.4): a rule-based planner whose SE(3)
// waypoints and gripper states are tracked by the model executor.
//
//   task::Expert expert(env);       // env: a task::TaskEnv
//   env.reset(spec);  expert.reset();
//   while (!env.done()) { expert.act(torques, S); env.step(torques, S); }
//
// A task is a list of moves "put object i at pose P" (the task type's moves() and move():
// moves.hpp), kept as the object stands (translation only) but for a task that states the yaw
// (ALN). For each move the expert chooses a grasp (grasp_choice.hpp), whose legs
// (expert_legs.hpp) pass the line checks (expert_checks.hpp), and runs it through a phase
// machine, one handler per phase:
//   approach  the approach leg's lines in turn;
//   descend   to the grasp (at approach.tight_peak_speed when the grasp is tight:
//             approach.tight_clearance);
//   close     once settled (the arm's tip slower than settle.speed); the place corrected for
//             where the object sits in the hand, with the target orientation's symmetric
//             equivalent nearest the held one, and the corrected carry checked again (when
//             refused, the other kind of carry tried);
//   carry     the carry leg's lines, then, once the arm's tip is slower than carry.settle_speed,
//   lower     at lower.peak_speed (a long lower into a container at the carry's speed until
//             lower.slow_distance above its end first); a tall object (height above
//             release.tall_ratio x width) is lowered on until its support carries it,
//             lower.contact_depth below, the arm stopped there, release.lift up;
//   open      once settled, or as soon as the support carries the object or the gripper touches
//             anything else (fingers_blocked; a tall one once the arm's tip is slower than
//             release.settle_speed);
//   retract   (a tall object: once the opening fingers clear it by release.clearance on each
//             side) up at retract.peak_speed until the fingertips clear the object's top, also
//             after the last move; then the next move.
// A missed grasp re-opens and retries the move from its approach (approach.max_retries); so does,
// backing off along its approach with the gripper open, a descent that ends approach.grasp_error
// short of its grasp or a grasp whose carry no longer passes from where the object sits in the
// hand, the move then planned without that grasp. A line the executor refuses while running (it
// starts from where the arm's shape target is, not the planned pose) falls back to a shape ramp.
// The executor's stiffness estimate is frozen while the tool may touch something (descend, close,
// lower, open: ModelExecutor::freeze_estimate).
// Deterministic; allocation only when a move is planned, its carry re-checked at the grasp or a
// ramp set up (path set-ups copy the executor).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cstddef>
#include <optional>
#include <string_view>
#include <vector>

#include "manisoft/control/arm_observation.hpp"
#include "manisoft/control/model_executor.hpp"
#include "manisoft/task/expert_config.hpp"
#include "manisoft/task/grasp_choice.hpp"
#include "manisoft/task/moves.hpp"
#include "manisoft/task/task_env.hpp"

namespace manisoft::task {

class Expert : private detail::GraspChoice {
 public:
  using Pose = math::Pose<double>;
  using Vec3 = Eigen::Vector3d;
  using Array3 = TaskEnv::Array3;
  using Executor = TaskEnv::Executor;

  explicit Expert(const TaskEnv& env, ExpertConfig config = {}) : GraspChoice(env, config), executor_(env.home_executor()) {
    const int n = env.arm_model().rod.n_elements;
    observation_ = control::make_arm_observation<double>(n, env.config().observe_stride);
    events_.reserve(64);
  }

  /// Starts the episode of the env's current scene (call after env.reset()).
  void reset() {
    executor_ = env_->home_executor();
    target_ = env_->home_pose();
    move_ = 0;
    retries_ = 0;
    excluded_.clear();
    s_ = 0;
    waited_ = 0;
    touched_ = false;
    lower_fast_ = false;
    steps_ = 0;
    events_.clear();
    failure_.reset();
    moves_ = count_moves();
    begin_move();
  }

  /// The action of the next control step (torques n x 3 and gripper state S), from the env's
  /// privileged state. Call once per env.step().
  void act(Array3& torques, int& s) {
    const auto& w = env_->world();
    if (steps_ > 0) advance(w);
    control::observe_arm(w, target_, observation_);
    executor_.act(observation_, torques);
    s = s_;
    ++steps_;
  }

  ExpertPhase phase() const { return phase_; }
  /// The end-effector pose the executor tracks now: the end of the current line or ramp (the
  /// home pose after reset()); what an end-effector-track policy would command
  /// (ee_track.hpp).
  const Pose& target() const { return target_; }
  int move() const { return move_; }
  int moves() const { return moves_; }
  /// Why the expert gave up (none while it has not): a path the executor refused, a missed grasp.
  /// The text lives as long as the expert, until its next reset().
  std::optional<std::string_view> failure() const { return failure_; }
  const std::vector<ExpertEvent>& events() const { return events_; }
  const Executor& executor() const { return executor_; }

 private:
  /// The grasp of move k: the feasible candidate that turns least (grasp_choice.hpp).
  bool plan_move(int k) {
    const auto [object, target] = move_goal(k);
    const std::vector<Candidate> candidates = grasp_candidates(object, target, support_of(k), executor_.statics().desired_tip_pose());
    plan_refusal_ = candidates.empty() ? "the asset has no grasp annotation" : "";
    // first pass: straight lines only; second: refused lines repaired (check_leg)
    for (int pass = 0; pass < 2; ++pass) {
      const detail::LinePlan lines(object, pass == 1);
      // (a re-try, whose first grasp failed, searches straight lines only: the repair pass checks
      // every candidate again, about 0.5 s when none passes)
      if (lines.repair && (!config_.paths.ramp_fallback || retries_ > 0)) break;
      for (auto c : candidates) {
        if (check_candidate(c.plan, k, executor_, lines)) {
          plan_ = c.plan;
          return true;
        }
      }
    }
    return false;
  }
  void begin_move() {
    waited_ = 0;
    if (move_ >= moves_) {
      enter(ExpertPhase::idle);
      return;
    }
    if (!plan_move(move_)) {
      plan_refusal_ = "no feasible grasp (the least-turning one: " + plan_refusal_ + ")";
      give_up(plan_refusal_);
      return;
    }
    leg_ = 0;
    enter(ExpertPhase::approach);
    start_leg(plan_.approach_leg, 0);
  }
  void enter(ExpertPhase p) {
    phase_ = p;
    executor_.freeze_estimate(config_.paths.freeze_estimate_in_contact && (p == ExpertPhase::descend || p == ExpertPhase::close ||
                                                                     p == ExpertPhase::lower || p == ExpertPhase::open));
    if (events_.size() < events_.capacity()) {
      ExpertEvent e;
      e.step = steps_;
      e.move = move_;
      e.phase = p;
      e.position = env_->world().soft().end_effector_frame().position;
      events_.push_back(e);
    }
  }
  /// Backs off along the descent to the approach pose (gripper open) and plans the move again
  /// without this grasp (approach.max_retries); false, nothing changed, when no re-try is left.
  bool retry_with_another_grasp() {
    if (retries_ >= config_.approach.max_retries || plan_.object < 0) return false;
    ++retries_;
    s_ = 0;
    excluded_.push_back(state_of(plan_.object).pose.inverse() * plan_.grasp);
    enter(ExpertPhase::retract);
    if (!start_path(plan_.approach_leg.pose[static_cast<std::size_t>(plan_.approach_leg.count - 1)], false)) begin_move();
    return true;
  }
  void give_up(std::string_view why) {
    failure_ = why;
    enter(ExpertPhase::failed);
  }
  /// Starts the path to `goal`; a refused one ends the episode's plan (give_up) when `required`.
  bool start_path(const Pose& goal, bool required = true, double peak_speed = 0) {
    const double distance = (goal.translation - executor_.statics().desired_tip_pose().translation).norm();
    const bool loaded = s_ == 1;
    const int steps = line_steps(distance, loaded, peak_speed, plan_.object);
    const auto report = executor_.track_line(goal, steps, node_step(loaded), config_.paths.cruise);
    if (!report.accepted) {
      // the executor's shape ramp to the goal's cold solution instead, when it has one
      if (config_.paths.ramp_fallback && start_ramp(goal)) return true;
      if (required) give_up(report.reason);
      return false;
    }
    target_ = goal;
    return true;
  }
  /// Starts the executor's shape ramp to `goal` (set_target); false (nothing changed but the
  /// executor's target) when the goal has no inverse statics solution within the limits.
  bool start_ramp(const Pose& goal) {
    planner_ = executor_;
    const auto r = planner_.set_target(goal);
    if (!r.within_limits) return false;
    executor_.set_target(goal);
    target_ = goal;
    return true;
  }
  /// Starts line i of a leg: a path, or a shape ramp (the executor's set_target).
  void start_leg(const Leg& leg, int i) {
    const auto k = static_cast<std::size_t>(i);
    if (!leg.ramp[k]) {
      start_path(leg.pose[k]);
      return;
    }
    if (!start_ramp(leg.pose[k])) give_up("a ramp target has no inverse statics solution within the actuation limits");
  }
  /// Whether the held object is let go only once the arm is still (release.settle_speed): a
  /// tall one.
  bool release_settles() const { return config_.release.settle_speed > 0 && is_tall(plan_.object); }
  /// The end of the lower line: the place pose; for a tall object (release_settles()) lowered on by
  /// lower.place_clearance + lower.contact_depth, so that it reaches its support and is not
  /// dropped. Onto an item (SupportKind::onto: STK): no lower than where the fingertips are
  /// lower.stack_finger_clearance above the item below's top (the closed fingers, at the held
  /// item's width, would land on its rim or inner wall before the held item nests); the item drops
  /// the rest of the way.
  Pose lower_goal() const {
    Pose p = plan_.place;
    if (release_settles() && config_.lower.contact_depth > 0) p.translation.z() -= config_.lower.place_clearance + config_.lower.contact_depth;
    if (const Support below = support_of(move_); below.kind == SupportKind::onto) {
      const double lowest = top_of(below.object) + config_.lower.stack_finger_clearance;
      p.translation.z() += std::max(0.0, lowest - fingertips(p).z());
    }
    return p;
  }
  /// Whether something under the held object carries it (see the lower phase).
  bool supported(const ObjectState& o) const {
    return o.touching != 0 || o.touches_table || o.pose.translation.z() < plan_.object_target.translation.z() - 0.5 * config_.lower.place_clearance;
  }
  /// Whether the gripper touches anything but the held object: the closed fingers, at the held
  /// object's width, land on the rim or inner wall of a bowl below before the held bowl nests in
  /// it (the lower then opens there and the object drops the rest of the way).
  bool fingers_blocked(const TaskEnv::World& w) const {
    const rigid::BodyId g = w.gripper_body(), held = env_->bodies().objects[static_cast<std::size_t>(plan_.object)];
    for (const auto& m : w.rigid().manifolds()) {
      if (m.body_a != g && m.body_b != g) continue;
      if ((m.body_a == g ? m.body_b : m.body_a) != held && TaskEnv::touching(m)) return true;
    }
    return false;
  }
  /// Above the place pose by retract.height, or more until the fingertips are
  /// retract.finger_clearance above the released object's top.
  Pose retract_pose() const {
    Pose up = plan_.place;
    up.translation.z() += std::max(config_.retract.height, top_of(plan_.object) + config_.retract.finger_clearance - fingertips(plan_.place).z());
    return up;
  }
  /// Whether the open fingers clear the object by less than approach.tight_clearance on each side
  /// (a plate, a bowl, a shoe): the arm then descends at approach.tight_peak_speed, since its
  /// sideways sway on a fast descent lands a finger on the object's rim and tips it.
  bool tight_grasp() const {
    return 0.5 * (env_->gripper_parameters().open_width - plan_.width) < config_.approach.tight_clearance;
  }

  /// How near the end of line leg_ of `leg` the arm must be for the next path to start:
  /// paths.via_error at an arc or via point, paths.start_error at the leg's last pose.
  double chain_error(const Leg& leg) const { return leg_ + 1 < leg.count ? config_.paths.via_error : config_.paths.start_error; }
  /// What the phase handlers read of the world after a control step.
  struct Tick {
    const TaskEnv::World& world;
    Pose ee;         ///< the end-effector frame
    double error;    ///< m: the end-effector from its target
    double speed;    ///< m/s: the arm's tip
    bool done;       ///< the executor's path is complete
    bool settled;    ///< done, slower than settle.speed and within settle.error
    bool holding;    ///< the gripper holds the moved object
  };
  Tick observe_tick(const TaskEnv::World& w) const {
    const auto f = w.soft().end_effector_frame();
    const double error = (f.position - target_.translation).norm();
    const auto& v = w.rod().state().velocities;
    const double speed = v.row(v.rows() - 1).norm();
    const bool done = executor_.path_done();
    const bool settled = done && speed < config_.settle.speed && error < config_.settle.error;
    const auto held = w.gripper().held();
    const bool holding = held && plan_.object >= 0 && *held == env_->bodies().objects[static_cast<std::size_t>(plan_.object)];
    return Tick{w, Pose{f.rotation, f.position}, error, speed, done, settled, holding};
  }
  /// The phase machine, after the last control step: one handler per phase.
  void advance(const TaskEnv::World& w) {
    const Tick t = observe_tick(w);
    switch (phase_) {
      case ExpertPhase::approach: advance_approach(t); break;
      case ExpertPhase::descend: advance_descend(t); break;
      case ExpertPhase::close: advance_close(t); break;
      case ExpertPhase::carry: advance_carry(t); break;
      case ExpertPhase::lower: advance_lower(t); break;
      case ExpertPhase::open: advance_open(t); break;
      case ExpertPhase::retract:
        if (t.done && t.error < config_.paths.start_error) begin_move();
        break;
      case ExpertPhase::idle:
      case ExpertPhase::failed: break;
    }
  }
  /// Approach: the approach leg's lines in turn, then the descent to the grasp.
  void advance_approach(const Tick& t) {
    if (!(t.done && t.error < chain_error(plan_.approach_leg))) return;
    if (leg_ + 1 < plan_.approach_leg.count) {
      start_leg(plan_.approach_leg, ++leg_);
      return;
    }
    enter(ExpertPhase::descend);
    start_path(plan_.grasp, true, tight_grasp() ? config_.approach.tight_peak_speed : 0.0);
  }
  /// Descend: at the grasp once settled, close.
  void advance_descend(const Tick& t) {
    if (!(t.done && (t.settled || ++waited_ > config_.settle.max_steps))) return;
    waited_ = 0;
    // blocked short of the grasp (a finger on the object): the hand would close around
    // the object askew, and its carry is then mostly beyond the actuation limits
    if (t.error > config_.approach.grasp_error && retry_with_another_grasp()) return;
    s_ = 1;
    enter(ExpertPhase::close);
  }
  /// Close: once the object is held, the place corrected for where it sits in the hand and the
  /// carry checked from there; a missed grasp re-tries the move.
  void advance_close(const Tick& t) {
    if (!t.holding && t.world.gripper().closing()) return;  // the fingers are still on their way
    if (!t.holding) {
      s_ = 0;
      if (retries_++ < config_.approach.max_retries) {
        begin_move();
      } else {
        give_up("missed grasp");
      }
      return;
    }
    const Pose object = state_of(plan_.object).pose;
    correct_place(t.ee, object);
    // neither carry passes from where the object sits in the hand: put it back (it still
    // stands where it was grasped) and re-try with another grasp
    if (!recheck_carry(t.ee, object) && retries_ < config_.approach.max_retries) {
      executor_.set_payload(0.0);
      retry_with_another_grasp();
      return;
    }
    leg_ = 0;
    enter(ExpertPhase::carry);
    start_leg(plan_.carry_leg, 0);
  }
  /// Where the object sits in the hand (end-effector at `ee`, the object at `object`): the
  /// payload hint, the target orientation nearest the one this grasp releases it in, the place
  /// pose and the carry leg from there.
  void correct_place(const Pose& ee, const Pose& object) {
    const auto& a = asset_of(plan_.object);
    executor_.set_payload(a.mass, ee.rotation.transpose() * (object.act(a.center_of_mass) - ee.translation));
    {
      // the object's target orientation nearest the one this grasp would release it in
      const Eigen::Matrix3d would_be = (plan_.place * ee.inverse() * object).rotation;
      const auto symmetry = yaw_free(plan_.object) ? scene::Symmetry{scene::Symmetry::Kind::axial, 0} : scene::asset_symmetry(a);
      plan_.object_target.rotation = nearest_equivalent(would_be, plan_.object_target.rotation, symmetry);
    }
    plan_.place = plan_.object_target * object.inverse() * ee;
    set_carry_leg(plan_);
  }
  /// The corrected carry, checked (and repaired) from here; when it is refused, the other kind
  /// (direct or via the lift). True (plan_ takes the carry that passed) when one passes; false
  /// (plan_ keeps the planned kind as corrected) when both are refused.
  bool recheck_carry(const Pose& ee, const Pose& object) {
    for (const bool via : {plan_.via_carry, !plan_.via_carry}) {
      Plan checked = plan_;
      checked.via_carry = via;
      set_carry_leg(checked);
      planner_ = executor_;
      planner_.complete_path();
      const detail::LinePlan lines(plan_.object, true);
      const char* why = "";
      if (check_carry_leg(checked, ee, object, support_of(move_).object, lines, why) && check_line(checked.place, lines, why)) {
        plan_ = checked;
        return true;
      }
    }
    return false;
  }
  /// Carry: the carry leg's lines in turn, then (once the arm's tip is slower than
  /// carry.settle_speed) the lower.
  void advance_carry(const Tick& t) {
    if (!t.holding) {
      give_up("dropped the object");
      return;
    }
    if (!(t.done && t.error < chain_error(plan_.carry_leg))) return;
    if (leg_ + 1 < plan_.carry_leg.count) {
      start_leg(plan_.carry_leg, ++leg_);
    } else if (!(config_.carry.settle_speed > 0) || t.speed < config_.carry.settle_speed || ++waited_ > config_.settle.max_steps) {
      waited_ = 0;
      enter(ExpertPhase::lower);
      // a long lower (into a container) runs at the carry's speed to lower.slow_distance above its
      // end first
      Pose fast = lower_goal();
      fast.translation.z() += config_.lower.slow_distance;
      lower_fast_ = config_.lower.slow_distance > 0 && target_.translation.z() - fast.translation.z() > config_.lower.slow_distance;
      start_path(lower_fast_ ? fast : lower_goal(), true, lower_fast_ ? 0.0 : config_.lower.peak_speed);
    }
  }
  /// Lower: the fast line first (lower.slow_distance), then the slow one; open once the object is
  /// supported (or the fingers blocked) or the lower settled.
  void advance_lower(const Tick& t) {
    if (!t.holding) {
      give_up("dropped the object");
      return;
    }
    if (lower_fast_ && !supported(state_of(plan_.object))) {
      if (t.done && t.error < config_.paths.start_error) {
        lower_fast_ = false;
        // refused: the object is lower.slow_distance above its release height already (into a
        // container: mostly below the rim), so it is let go from here once settled
        start_path(lower_goal(), false, config_.lower.peak_speed);
      }
      return;
    }
    lower_fast_ = false;
    // Its support already carries the object (it touches the table or another object, or
    // sank half the clearance below the release height): open now rather than press it in
    // until it slips.
    // With release.settle_speed, the arm stops where it is first and opens once its tip is
    // slower (a tall object let go while the arm still sways tips over).
    if (!touched_ && (supported(state_of(plan_.object)) || fingers_blocked(t.world))) {
      touched_ = true;
      waited_ = 0;
      if (release_settles()) {
        Pose hold = t.ee;  // where the arm is, lifted so it does not press on
        hold.translation.z() += config_.release.lift;
        start_path(hold, false);
      }
    }
    if (touched_ ? (!release_settles() || t.speed < config_.release.settle_speed || ++waited_ > config_.settle.max_steps)
                 : (t.done && (t.settled || ++waited_ > config_.settle.max_steps))) {
      touched_ = false;
      waited_ = 0;
      s_ = 0;
      executor_.set_payload(0.0);
      enter(ExpertPhase::open);
    }
  }
  /// Open: once the opening fingers clear a tall object (release.clearance), the retract; the
  /// next move starts from there.
  void advance_open(const Tick& t) {
    const auto& g = t.world.gripper();
    if (is_tall(plan_.object) && g.opening() && g.finger_width() < plan_.width + 2 * config_.release.clearance) return;
    // Up and away from the released object, also after the last move (fingers left
    // around it keep pushing it as the arm sways, and it never comes to rest).
    ++move_;
    retries_ = 0;
    excluded_.clear();
    enter(ExpertPhase::retract);
    // a refused retract is not a failure: the next move plans from here, or the arm holds
    if (!start_path(retract_pose(), false, config_.retract.peak_speed)) {
      if (move_ < moves_) begin_move();
      else enter(ExpertPhase::idle);
    }
  }

  Executor executor_;
  control::Observation<double> observation_;
  Pose target_;
  Plan plan_;
  ExpertPhase phase_ = ExpertPhase::idle;
  int move_ = 0, moves_ = 0, retries_ = 0, s_ = 0, waited_ = 0, leg_ = 0;
  long steps_ = 0;
  std::vector<ExpertEvent> events_;
  std::optional<std::string_view> failure_;
  bool touched_ = false;      ///< the lower phase found the object supported
  bool lower_fast_ = false;   ///< the lower phase's first, fast line (lower.slow_distance)
};

}  // namespace manisoft::task
