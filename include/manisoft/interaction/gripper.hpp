// ParallelGripper: the paper's end-effector with state S in {0, 1} (section 3.2, action
// A_t = (tau_e, S)): a rigid compound body (palm box and two finger boxes, all colliding with the
// world) and a grasp mechanism.
//
// Geometry, in the gripper's shape frame (= the attachment frame, see make_parallel_gripper):
// origin at the centre of the palm's top face, where the rod tip meets it; +z (the tip's d3)
// points into the palm and on along the fingers; +x (d1) is the closing axis; y = z x x (d2).
// The palm spans z in [0, palm_thickness]; the fingers hang below it, from z = palm_thickness to
// palm_thickness + finger_length, their inner faces at x = +-open_width / 2. The grasp region is
// the box between the inner faces over the fingers' length and width.
//
// Fingers: the two finger boxes are geometry of the gripper body that moves along the closing
// axis (RigidWorld::set_geom_translation): the gap between their inner faces goes from open_width
// to 0 in stroke_time (both fingers at open_width / (2 stroke_time)), so they collide with what is
// between them at every width and a closed gripper never passes through an object; the body's
// mass properties stay those of the open gripper. The contact solver sees the finger surfaces
// move (RigidGeom::surface_velocity), so a closing finger pushes what it meets at its own speed.
//
// Grasp mechanism (a weld with a friction limit): while the fingers close, the first dynamic
// body that both fingers touch (within touch_tolerance; ties: lowest id) is welded to the gripper
// at its current relative pose, and the fingers stop there (finger_width() = the gap at the
// grasp). The weld is a stiff 6-DoF spring-damper (k, c = zeta 2 sqrt(k m_eff); k_r, c_r on the
// pair's smallest inertia I_eff), integrated implicitly (backward Euler on the pair's relative
// motion, Box2D's soft step), so it is stable at any stiffness and time step:
//   F = -(k dx + (c + h k) dv) / (1 + h (c + h k) / m_eff),   dx = x_o - x_a, dv = v_o - v_a
//   M = -(k_r dtheta + (c_r + h k_r) dw) / (1 + h (c_r + h k_r) / I_eff),  dtheta = Log(R_o R_a^T)
// on the object at its centre of mass x_o, the opposite force at x_o on the gripper and the
// opposite torque (so the pair conserves momentum); x_a, R_a: the object's pose frozen in the
// gripper frame at the grasp; m_eff, I_eff: the pair's reduced mass and inertia. The held object
// keeps colliding with everything (table, obstacles, other objects, the rod) but the gripper
// itself while it is held (RigidWorld::set_excluded_contact): the weld is the grip, and the
// fingers stopped within touch_tolerance of it (or a palm it touches) would only add contacts
// that fight the weld and are re-detected at every step of a carry; once it slips or is released,
// they are found again. Closing on nothing closes the fingers to 0 and grasps nothing (a closed
// gripper picks up nothing it bumps into later); S 1 -> 0 removes the weld at once and the fingers
// open at the stroke speed.
//
// The grip is friction: the fingers press with a normal force N each; the grip carries at most
// max_hold_force = 2 mu N (40 N for N = 25 N, mu = 0.8) and max_hold_torque (1.5 N m: that force
// at a 3.75 cm arm, about the width of the 4 cm finger pads). A weld force or
// torque beyond them is capped there and the object slides (its anchor follows it: kinetic
// friction); an object that has slid max_slide (2 cm) from where it was grasped slips out and the
// grasp ends (reported by `slipped()`); the fingers then stay where they stopped until opened.
// Opening is force-limited: while anything presses on a finger's outer face (the wall of a bowl
// the closed fingers were lowered into), the fingers stop, and go on opening once the arm lifts
// them clear.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "manisoft/assets/asset.hpp"
#include "manisoft/contact/narrow_phase.hpp"
#include "manisoft/core/error.hpp"
#include "manisoft/math/so3.hpp"
#include "manisoft/rigid/rigid_world.hpp"
#include "manisoft/interaction/end_effector.hpp"
#include "manisoft/interaction/stable_spring.hpp"

namespace manisoft::interaction {

struct ParallelGripperParameters {
  double palm_half_x = 0.06;       ///< m, along the closing axis
  double palm_half_y = 0.05;       ///< m
  double palm_thickness = assets::GraspGripper{}.palm_thickness;  ///< m, along the approach axis (>= the rod radius:
                                                                 ///< the tip's rounded end cap stays inside the palm)
  double finger_thickness = 0.01;  ///< m, along the closing axis
  double finger_half_width = 0.02; ///< m, along y
  double finger_length = assets::GraspGripper{}.finger_length;  ///< m, below the palm
  double open_width = assets::GraspGripper{}.open_width;        ///< m, between the inner finger faces
  double mass = 0.2;               ///< kg (the coupling's design load)
  double friction = 0.8;
  double weld_stiffness = 2e4;            ///< N/m
  double weld_rotational_stiffness = 50;  ///< N m/rad
  double weld_damping_ratio = 0.7;
  double max_hold_force = 40;      ///< N: grip friction limit (2 fingers x 25 N x mu 0.8)
  double max_hold_torque = 1.5;    ///< N m: max_hold_force at a 3.75 cm arm (about the finger pads' width)
  double max_slide = 0.02;         ///< m: an object that slides this far in the grip slips out
  double stroke_time = 0.1;        ///< s: fingers from open to closed (the gap closes at open_width / stroke_time)
  double touch_tolerance = 5e-4;   ///< m: a finger this near a body touches it (the grasp's check)

  void validate() const {
    manisoft::detail::require_positive("ParallelGripper palm_half_x", palm_half_x);
    manisoft::detail::require_positive("ParallelGripper palm_half_y", palm_half_y);
    manisoft::detail::require_positive("ParallelGripper palm_thickness", palm_thickness);
    manisoft::detail::require_positive("ParallelGripper finger_thickness", finger_thickness);
    manisoft::detail::require_positive("ParallelGripper finger_half_width", finger_half_width);
    manisoft::detail::require_positive("ParallelGripper finger_length", finger_length);
    manisoft::detail::require_positive("ParallelGripper open_width", open_width);
    manisoft::detail::require_positive("ParallelGripper mass", mass);
    manisoft::detail::require_non_negative("ParallelGripper friction", friction);
    manisoft::detail::require_positive("ParallelGripper weld_stiffness", weld_stiffness);
    manisoft::detail::require_positive("ParallelGripper weld_rotational_stiffness", weld_rotational_stiffness);
    manisoft::detail::require_non_negative("ParallelGripper weld_damping_ratio", weld_damping_ratio);
    manisoft::detail::require_positive("ParallelGripper max_slide", max_slide);
    manisoft::detail::require_positive("ParallelGripper max_hold_force", max_hold_force);
    manisoft::detail::require_positive("ParallelGripper max_hold_torque", max_hold_torque);
    manisoft::detail::require_positive("ParallelGripper stroke_time", stroke_time);
    manisoft::detail::require_non_negative("ParallelGripper touch_tolerance", touch_tolerance);
    if (palm_half_x < 0.5 * open_width + finger_thickness - 1e-9) {
      manisoft::detail::fail("ParallelGripper palm_half_x = ", palm_half_x, " must cover the fingers (open_width / 2 + finger_thickness = ",
                   0.5 * open_width + finger_thickness, ")");
    }
  }
  /// Centre of the grasp region in the gripper frame.
  Eigen::Vector3d grasp_center() const { return {0, 0, palm_thickness + 0.5 * finger_length}; }
  /// Centre of finger `side` (-1 or +1) in the gripper frame at finger gap `gap`.
  Eigen::Vector3d finger_center(double side, double gap) const {
    return {side * (0.5 * gap + 0.5 * finger_thickness), 0, palm_thickness + 0.5 * finger_length};
  }
};

/// The gripper as an end-effector: compound body (palm + two fingers), attached at the palm's top
/// centre with the attach frame equal to the shape frame (d1 = x closing axis, d3 = z approach).
inline interaction::EndEffectorDesc make_parallel_gripper(const ParallelGripperParameters& p = {}) {
  p.validate();
  geometry::Compound<double> c;
  geometry::CompoundPart<double> palm;
  palm.shape = geometry::Box<double>{Eigen::Vector3d(p.palm_half_x, p.palm_half_y, 0.5 * p.palm_thickness)};
  palm.position = Eigen::Vector3d(0, 0, 0.5 * p.palm_thickness);
  c.parts.push_back(palm);
  for (double side : {-1.0, 1.0}) {
    geometry::CompoundPart<double> finger;
    finger.shape = geometry::Box<double>{Eigen::Vector3d(0.5 * p.finger_thickness, p.finger_half_width, 0.5 * p.finger_length)};
    finger.position = p.finger_center(side, p.open_width);
    c.parts.push_back(finger);
  }
  interaction::EndEffectorDesc ee;
  ee.body.shape = c;
  ee.body.mass = p.mass;
  ee.body.friction = p.friction;
  ee.body.name = "gripper";
  ee.attach_position.setZero();
  ee.attach_rotation.setIdentity();
  return ee;
}

/// Grasp state machine and weld of a ParallelGripper body (see the header comment).
class ParallelGripper {
 public:
  using Vec3 = Eigen::Vector3d;
  using Mat3 = Eigen::Matrix3d;

  /// Everything a world step changes in the gripper: command and state S, the held object and
  /// its weld (anchor, stiffnesses), the last step's weld wrench and events. A plain value: a
  /// world's rollback copies it whole.
  struct Snapshot {
    int command = 0, state = 0;
    double gap = 0;        ///< m: between the fingers' inner faces
    double gap_rate = 0;   ///< m/s: how fast the gap changed in the last step (the fingers' surface speed x 2)
    bool stopped = false;  ///< the fingers stopped on a grasped object (until opened)
    std::optional<rigid::BodyId> held, last_released;
    Vec3 anchor_local = Vec3::Zero();
    Mat3 rotation_local = Mat3::Identity();
    double k = 0, k_r = 0, c = 0, c_r = 0;
    double m_eff = 0, i_eff = 0;  ///< the pair's reduced mass and inertia (the implicit weld's)
    Vec3 grasp_anchor_local = Vec3::Zero();  ///< anchor_local at the grasp (the object slides from there)
    Vec3 weld_force = Vec3::Zero(), weld_torque = Vec3::Zero();
    bool grasped_now = false, released_now = false, slipped = false;
  };
  void save(Snapshot& out) const { out = m_; }
  void restore(const Snapshot& in) { m_ = in; }

  ParallelGripper() : ParallelGripper(ParallelGripperParameters{}) {}
  explicit ParallelGripper(const ParallelGripperParameters& p) : params_(p) {
    params_.validate();
    m_.gap = params_.open_width;
  }

  const ParallelGripperParameters& parameters() const { return params_; }
  /// The rigid body that carries the gripper geometry (made from make_parallel_gripper).
  void attach(rigid::BodyId body) { body_ = body; }
  rigid::BodyId body() const { return body_; }

  /// Commands S (0 open, 1 closed); takes effect at the next pre_step.
  void command(int s) {
    if (s != 0 && s != 1) manisoft::detail::fail("ParallelGripper::command: S = ", s, " must be 0 (open) or 1 (closed)");
    m_.command = s;
  }
  int command_state() const { return m_.command; }
  /// The state S the gripper is in (after the last pre_step).
  int state() const { return m_.state; }
  std::optional<rigid::BodyId> held() const { return m_.held; }
  /// Distance between the fingers' inner faces [m] (see the header comment).
  double finger_width() const { return m_.gap; }
  /// Commanded closed, the fingers still moving and nothing grasped yet.
  bool closing() const { return m_.state == 1 && !m_.held && !m_.stopped && m_.gap > 0; }
  /// Commanded open and the fingers not yet fully open.
  bool opening() const { return m_.state == 0 && m_.gap < params_.open_width; }
  /// The weld wrench on the held object in the last step (lab); grip_force() = |weld_force()|,
  /// at most max_hold_force (the object slides when it is there).
  const Vec3& weld_force() const { return m_.weld_force; }
  const Vec3& weld_torque() const { return m_.weld_torque; }
  double grip_force() const { return m_.weld_force.norm(); }
  /// How far the held object has slid in the grip since it was grasped, m.
  double slide() const { return (m_.anchor_local - m_.grasp_anchor_local).norm(); }
  /// Events of the last pre_step.
  bool grasped_now() const { return m_.grasped_now; }
  bool released_now() const { return m_.released_now; }
  bool slipped() const { return m_.slipped; }
  std::optional<rigid::BodyId> last_released() const { return m_.last_released; }

  /// World pose of the grasp region centre.
  Vec3 grasp_point(const rigid::RigidWorld& world) const {
    return world.position(body_) + world.orientation(body_).toRotationMatrix() * params_.grasp_center();
  }

  /// Before each world step: handles S transitions, moves the fingers, grasps what both touch,
  /// applies the weld wrench, checks slip.
  void pre_step(rigid::RigidWorld& world, double dt) {
    m_.grasped_now = m_.released_now = m_.slipped = false;
    m_.weld_force.setZero();
    m_.weld_torque.setZero();
    if (m_.command != m_.state) {
      m_.state = m_.command;
      if (m_.state == 0) {
        if (m_.held) release();
        m_.stopped = false;
      }
    }
    const double rate = params_.open_width / params_.stroke_time;
    double gap = m_.state == 1 ? (m_.stopped ? m_.gap : std::max(0.0, m_.gap - rate * dt))
                               : std::min(params_.open_width, m_.gap + rate * dt);
    if (gap > m_.gap && opening_blocked(world)) gap = m_.gap;
    const double gap_rate = (gap - m_.gap) / dt;
    if (gap != m_.gap || gap_rate != m_.gap_rate) {
      const bool moved = gap != m_.gap;
      m_.gap = gap;
      m_.gap_rate = gap_rate;
      place_fingers(world, moved);
      if (moved && m_.state == 1) {
        if (auto b = touched_by_both(world)) start_weld(world, *b);
      }
    }
    if (m_.held) apply_weld(world, dt);
    exclude_held(world);
  }

  /// Puts the finger geometry where the state has it (after a restore: the contact caches are
  /// those of that state, so nothing is re-detected).
  void sync(rigid::RigidWorld& world) const {
    place_fingers(world, false);
    exclude_held(world);
  }

 private:
  void release() {
    m_.last_released = m_.held;
    m_.held.reset();
    m_.released_now = true;
  }

  static double smallest_inertia(const rigid::RigidBodyModel& m) {
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(m.inertia);
    return eig.eigenvalues().minCoeff();
  }

  void start_weld(rigid::RigidWorld& world, rigid::BodyId b) {
    m_.held = b;
    m_.grasped_now = true;
    const Mat3 rg = world.orientation(body_).toRotationMatrix();
    const Vec3 xg = world.position(body_);
    const Vec3 xo = world.center_of_mass(b);
    m_.anchor_local = rg.transpose() * (xo - xg);
    m_.rotation_local = rg.transpose() * world.orientation(b).toRotationMatrix();
    const auto& m = world.model(b);
    m_.stopped = true;
    // Stiffness caps on the pair's reduced mass and inertia (the force acts at x_o, a lever
    // |x_o - x_g,com| on the gripper).
    const auto& mg = world.model(body_);
    const double lever2 = (xo - world.center_of_mass(body_)).squaredNorm();
    const double inv_m = m.inverse_mass + mg.inverse_mass + lever2 * mg.inverse_inertia.norm();
    const double inv_i = 1.0 / smallest_inertia(m) + 1.0 / smallest_inertia(mg);
    m_.m_eff = 1.0 / inv_m;
    m_.i_eff = 1.0 / inv_i;
    m_.grasp_anchor_local = m_.anchor_local;
    m_.k = params_.weld_stiffness;
    m_.k_r = params_.weld_rotational_stiffness;
    m_.c = damping_for_ratio(params_.weld_damping_ratio, m_.k, m_.m_eff);
    m_.c_r = damping_for_ratio(params_.weld_damping_ratio, m_.k_r, m_.i_eff);
  }

  void apply_weld(rigid::RigidWorld& world, double h) {
    const rigid::BodyId b = *m_.held;
    const Mat3 rg = world.orientation(body_).toRotationMatrix();
    const Vec3 xa = world.position(body_) + rg * m_.anchor_local;
    const Vec3 xo = world.center_of_mass(b);
    const Mat3 ra = rg * m_.rotation_local;
    const Mat3 ro = world.orientation(b).toRotationMatrix();
    const Vec3 dtheta = math::so3::log(Mat3(ro * ra.transpose()));  // lab axis
    const Vec3 va = world.velocity_at_point(body_, xa);
    const Vec3 dv = world.linear_velocity(b) - va;
    const Vec3 dw = world.angular_velocity(b) - world.angular_velocity(body_);
    // Implicit (backward Euler) spring-damper on the pair's relative motion: stable at any stiffness.
    const double cf = m_.c + h * m_.k, cr = m_.c_r + h * m_.k_r;
    Vec3 force = -(m_.k * (xo - xa) + cf * dv) / (1 + h * cf / m_.m_eff);
    Vec3 torque = -(m_.k_r * dtheta + cr * dw) / (1 + h * cr / m_.i_eff);
    // Friction: the grip carries at most max_hold_force / max_hold_torque; beyond, the object
    // slides (the anchor follows it) and slips out once it has slid max_slide.
    if (force.norm() > params_.max_hold_force) {
      force *= params_.max_hold_force / force.norm();
      m_.anchor_local = rg.transpose() * (xo - world.position(body_));
      if (slide() > params_.max_slide) {
        m_.slipped = true;
        release();
        return;
      }
    }
    if (torque.norm() > params_.max_hold_torque) {
      torque *= params_.max_hold_torque / torque.norm();
      m_.rotation_local = rg.transpose() * ro;
    }
    m_.weld_force = force;
    m_.weld_torque = torque;
    world.add_force_and_torque(b, m_.weld_force, m_.weld_torque);
    world.add_force_at_point(body_, -m_.weld_force, xo);
    world.add_torque(body_, -m_.weld_torque);
  }

  /// The weld is the grip: the gripper's own contacts with what it holds (fingers stopped within
  /// touch_tolerance of it, a palm it was pressed against) are left out while it is held.
  void exclude_held(rigid::RigidWorld& world) const {
    if (!m_.held) return world.set_excluded_contact(std::nullopt);
    const auto& m = world.model(body_);
    world.set_excluded_contact(rigid::RigidWorld::ExcludedContact{m.first_geom, m.geom_count, *m_.held});
  }

  /// The finger geometries are the gripper compound's parts 1 (side -1) and 2 (side +1); each
  /// moves at half the gap's rate.
  void place_fingers(rigid::RigidWorld& world, bool redetect) const {
    const Vec3 com = world.model(body_).center_of_mass;
    for (int i = 0; i < 2; ++i) {
      const double side = i == 0 ? -1.0 : 1.0;
      const std::uint32_t g = world.model(body_).first_geom + std::uint32_t(1 + i);
      const Vec3 local = params_.finger_center(side, m_.gap) - com;
      const Vec3 velocity(0.5 * side * m_.gap_rate, 0, 0);
      if (redetect || world.geoms()[g].local.translation != local || world.geoms()[g].surface_velocity != velocity) {
        world.set_geom_translation(g, local, velocity, redetect);
      }
    }
  }

  /// Whether finger i (0: side -1, 1: side +1) touches body b within touch_tolerance; with
  /// `outward` (world, unit), only on its outer face (the contact normal within 60 degrees of it).
  bool finger_touches(rigid::RigidWorld& world, int i, rigid::BodyId b, const Vec3* outward) {
    const std::uint32_t fg = world.model(body_).first_geom + std::uint32_t(1 + i);
    const contact::Pose fp = world.geom_pose(fg);
    const auto& m = world.model(b);
    if ((world.center_of_mass(b) - fp.translation).norm() > m.bounding_radius + world.geoms()[fg].shape.bounding_radius + params_.touch_tolerance) {
      return false;
    }
    for (std::uint32_t g = m.first_geom; g < m.first_geom + m.geom_count; ++g) {
      if (!contact::collide(world.geoms()[fg].shape, fp, world.geoms()[g].shape, world.geom_pose(g), params_.touch_tolerance, set_, scratch_)) continue;
      if (outward && set_.normal.dot(*outward) < 0.5) continue;
      for (int k = 0; k < set_.count; ++k)
        if (set_.points[std::size_t(k)].separation <= params_.touch_tolerance) return true;
    }
    return false;
  }

  /// The dynamic body (lowest id) that both fingers touch, if any.
  std::optional<rigid::BodyId> touched_by_both(rigid::RigidWorld& world) {
    for (rigid::BodyId b = 0; b < world.body_count(); ++b) {
      if (b == body_ || world.model(b).is_static) continue;
      if (finger_touches(world, 0, b, nullptr) && finger_touches(world, 1, b, nullptr)) return b;
    }
    return std::nullopt;
  }

  /// Whether anything presses on a finger's outer face (the opening stops there).
  bool opening_blocked(rigid::RigidWorld& world) {
    const Vec3 x = world.orientation(body_).toRotationMatrix().col(0);
    const Vec3 outward[2] = {-x, x};
    for (rigid::BodyId b = 0; b < world.body_count(); ++b) {
      if (b == body_) continue;
      if (finger_touches(world, 0, b, &outward[0]) || finger_touches(world, 1, b, &outward[1])) return true;
    }
    return false;
  }

  ParallelGripperParameters params_;
  contact::ContactSet set_;
  contact::NarrowPhaseScratch scratch_;
  rigid::BodyId body_ = 0;
  Snapshot m_;  ///< everything a step changes (copied whole by a world's rollback)
};

}  // namespace manisoft::interaction
