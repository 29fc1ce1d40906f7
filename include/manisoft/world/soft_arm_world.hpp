// SoftArmWorld: the paper's hybrid simulator (section 3.1) without MuJoCo. A Cosserat rod (the
// soft arm) and a RigidWorld (end-effector, objects, table; FCL contact) advance in lock-step at
// the rod's time step, joined by a coupling policy between the rod's tip frame and the
// end-effector's attachment frame, with a rod-contact policy between rod elements and bodies and
// a device policy on the end-effector (the gripper's grasp logic).
//
//   using Rod = CosseratRod<double, damping::AnalyticalLinear, bc::ClampedBase,
//                           integrator::PositionVerlet, forcing::Gravity, forcing::ElementTorques>;
//   SoftArmWorld<Rod> world(std::move(rod), RigidWorldSettings{}, end_effector_desc);
//   world.rigid().add_body(object_desc);   // objects, table, obstacles
//   world.step();                          // one dt: device, coupling, contact, rod, rigid bodies
//
// Step (explicit, loads from the state at the start of the step):
//   0. one snapshot of everything the step changes (rod state and counter, rigid bodies and their
//      contact caches, rod-contact friction anchors, device state, counters),
//   1. device pre-step (gripper: S transitions, finger motion, weld wrench on a held object),
//   2. coupling wrench from the tip and attachment frames; -wrench on the rod tip,
//   3. rod contact loads (policy),
//   4. rod step, then +wrench on the end-effector and the rigid step.
// A failure (non-finite or diverging state: manisoft::Diverged; a non-finite load:
// manisoft::InvalidInput) puts every part back to the snapshot, drops the loads queued for the
// failed step, and rethrows with the step number: continuing from there is bit-identical to a run
// that never tried the step.
// Bodies that leave the workspace box are reported by `outside_workspace()`, never a crash.
// Movable (builders return worlds by value), not copyable.
#pragma once

#include <string>
#include <vector>

#include "manisoft/interaction/elastic_spring.hpp"
#include "manisoft/interaction/end_effector.hpp"
#include "manisoft/interaction/rod_contact.hpp"
#include "manisoft/rigid/rigid_world.hpp"
#include "manisoft/rod/cosserat_rod.hpp"

namespace manisoft::world {

/// An end-effector without a device (a plain rigid body on the coupling).
struct NoDevice {
  struct Snapshot {};
  void attach(rigid::BodyId) {}
  void pre_step(rigid::RigidWorld&, double) {}
  void save(Snapshot&) const {}
  void restore(const Snapshot&) {}
  void sync(rigid::RigidWorld&) const {}
};

template <typename Rod, typename Coupling = interaction::ElasticSpring, typename RodContact = interaction::NoRodContact,
          typename Device = NoDevice>
class SoftArmWorld {
 public:
  using Vec3 = Eigen::Vector3d;
  using SpringWrench = interaction::SpringWrench;

  /// Everything one step changes (see the header comment); sized at construction and reused.
  struct Snapshot {
    typename Rod::State rod;
    long rod_step_count = 0;
    rigid::RigidWorld::Snapshot rigid;
    typename RodContact::Snapshot rod_contact;
    typename Device::Snapshot device;
    interaction::SpringWrench last_wrench;
    long step_count = 0;
    bool full = true;  ///< false: a step snapshot (the rigid world and rod contact record the step)
  };

  SoftArmWorld(Rod rod, rigid::RigidWorldSettings settings, const interaction::EndEffectorDesc& end_effector, Coupling coupling = {},
               RodContact rod_contact = {}, Device device = {})
      : rod_(std::move(rod)), rigid_(std::move(settings)), coupling_(std::move(coupling)),
        rod_contact_(std::move(rod_contact)), device_(std::move(device)), attach_position_(end_effector.attach_position),
        attach_rotation_(end_effector.attach_rotation) {
    rigid::RigidBodyDesc desc = end_effector.body;
    if (end_effector.place_at_tip) {
      const auto tip = tip_frame();
      // body rotation R_b with R_b * attach_rotation = R_tip; body origin so the attach point sits at the tip.
      const Eigen::Matrix3d body_rotation = tip.rotation * attach_rotation_.transpose();
      desc.orientation = Eigen::Quaterniond(body_rotation);
      desc.position = tip.position - body_rotation * attach_position_;
    }
    end_effector_ = rigid_.add_body(desc);
    device_.attach(end_effector_);
    snapshot_.rod = rod_.state();  // sized once
    workspace_lo_ = Vec3::Constant(-10);
    workspace_hi_ = Vec3::Constant(10);
  }

  // ---- stepping
  void step() {
    save(snapshot_, /*full=*/false);
    rigid_.begin_step();
    try {
      advance();
    } catch (const Diverged& e) {
      restore(snapshot_);
      manisoft::detail::diverged(step_count_, e.where(), "SoftArmWorld step ", step_count_, ": ", e.what());
    } catch (const Error& e) {
      restore(snapshot_);
      manisoft::detail::fail("SoftArmWorld step ", step_count_, ": ", e.what());
    }
    ++step_count_;
    update_workspace_flags();
  }
  void step(int count) {
    for (int i = 0; i < count; ++i) step();
  }

  /// Saves everything a step changes (reuses `out`'s storage). A full snapshot (the default) can
  /// be restored after any number of steps; a step snapshot (`full` = false, what step() takes)
  /// leaves the rigid world and the rod contact to their own records of one step, which cost
  /// only what that step touches.
  void save(Snapshot& out, bool full = true) const {
    out.full = full;
    out.rod = rod_.state();
    out.rod_step_count = rod_.step_count();
    if (full) rigid_.save(out.rigid);
    rod_contact_.save(out.rod_contact, full);
    device_.save(out.device);
    out.last_wrench = last_wrench_;
    out.step_count = step_count_;
  }
  /// Puts every part back to `in` and drops the loads queued on the rod and the bodies.
  void restore(const Snapshot& in) {
    rod_.restore(in.rod, in.rod_step_count);
    rod_.state().external_forces.setZero();
    rod_.state().external_torques.setZero();
    if (in.full) {
      rigid_.restore(in.rigid);
    } else {
      rigid_.undo_step();
    }
    rigid_.clear_external_loads();
    rod_contact_.restore(in.rod_contact);
    device_.restore(in.device);
    device_.sync(rigid_);  // geometry the device moves (the fingers) back where the state has it
    last_wrench_ = in.last_wrench;
    step_count_ = in.step_count;
  }

  // ---- frames
  /// Rod tip frame: last node, last element's directors as columns, lab velocities.
  interaction::SpringFrame tip_frame() const {
    const auto& s = rod_.state();
    const int n = rod_.n_elements();
    const auto tip = s.tip_pose();
    interaction::SpringFrame f;
    f.position = tip.translation;
    f.rotation = tip.rotation;
    f.linear_velocity = s.velocity(n);
    f.angular_velocity = f.rotation * s.angular_velocity(n - 1);
    return f;
  }
  /// End-effector attachment frame.
  interaction::SpringFrame end_effector_frame() const {
    const auto& st = rigid_.state(end_effector_);
    interaction::SpringFrame f;
    const Eigen::Matrix3d r = rigid_.orientation(end_effector_).toRotationMatrix();
    f.position = rigid_.position(end_effector_) + r * attach_position_;
    f.rotation = r * attach_rotation_;
    f.linear_velocity = rigid_.velocity_at_point(end_effector_, f.position);
    f.angular_velocity = st.angular_velocity;
    return f;
  }

  // ---- workspace monitoring
  void set_workspace(const Vec3& lo, const Vec3& hi) {
    if (!(lo.array() < hi.array()).all()) manisoft::detail::fail("SoftArmWorld::set_workspace: lo must be below hi in every axis");
    workspace_lo_ = lo;
    workspace_hi_ = hi;
  }
  /// Bodies whose centre of mass has left the workspace box (reported, never an error).
  const std::vector<rigid::BodyId>& outside_workspace() const { return outside_; }

  // ---- access
  Rod& rod() { return rod_; }
  const Rod& rod() const { return rod_; }
  rigid::RigidWorld& rigid() { return rigid_; }
  const rigid::RigidWorld& rigid() const { return rigid_; }
  rigid::BodyId end_effector() const { return end_effector_; }
  const Coupling& coupling() const { return coupling_; }
  RodContact& rod_contact() { return rod_contact_; }
  const RodContact& rod_contact() const { return rod_contact_; }
  Device& device() { return device_; }
  const Device& device() const { return device_; }
  const interaction::SpringWrench& last_wrench() const { return last_wrench_; }
  long step_count() const { return step_count_; }
  double time() const { return double(step_count_) * double(rod_.dt()); }

 private:
  void advance() {
    const int n = rod_.n_elements();
    const double dt = double(rod_.dt());
    device_.pre_step(rigid_, dt);
    const interaction::SpringWrench w = coupling_.wrench(tip_frame(), end_effector_frame());
    last_wrench_ = w;
    const Eigen::Matrix3d q_last = rod_.state().director(n - 1);
    rod_.state().external_forces.row(n) -= w.force.transpose();
    rod_.state().external_torques.row(n - 1) -= (q_last * w.torque).transpose();
    rod_contact_.apply(rod_, rigid_);
    rod_.advance();
    rigid_.add_force_at_point(end_effector_, w.force, end_effector_frame().position);
    rigid_.add_torque(end_effector_, w.torque);
    rigid_.advance(dt);
  }

  void update_workspace_flags() {
    outside_.clear();
    if (outside_.capacity() < rigid_.body_count()) outside_.reserve(rigid_.body_count());  // only after bodies were added
    for (rigid::BodyId b = 0; b < rigid_.body_count(); ++b) {
      if (rigid_.model(b).is_static) continue;
      const Vec3 x = rigid_.center_of_mass(b);
      if ((x.array() < workspace_lo_.array()).any() || (x.array() > workspace_hi_.array()).any()) outside_.push_back(b);
    }
  }

  Rod rod_;
  rigid::RigidWorld rigid_;
  Coupling coupling_;
  RodContact rod_contact_;
  Device device_;
  Vec3 attach_position_;
  Eigen::Matrix3d attach_rotation_;
  Snapshot snapshot_;
  rigid::BodyId end_effector_ = 0;
  interaction::SpringWrench last_wrench_;
  long step_count_ = 0;
  Vec3 workspace_lo_, workspace_hi_;
  std::vector<rigid::BodyId> outside_;
};

}  // namespace manisoft::world
