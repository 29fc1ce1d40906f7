// ArmWorld: the ManiSoft scene (paper section 3.1-3.3): a SoftArmWorld (Cosserat rod + RigidWorld
// + elastic spring coupling) whose rod elements touch the world as capsules
// (interaction::RodCapsuleContact), a ParallelGripper as end-effector with state S, a table, static
// obstacles and dynamic objects.
//
//   using Rod = CosseratRod<double, damping::AnalyticalLinear, bc::ClampedBase,
//                           integrator::PositionVerlet, forcing::Gravity, forcing::ElementTorques>;
//   ArmWorld<Rod> world(Rod(params, 2e-4, damping), ArmWorldSettings{});
//   world.add_table({...});  world.add_object(desc);
//   world.control_step(torques, S);   // 7 substeps (714 Hz) with the torques and gripper state S
//
// Step: the SoftArmWorld step (gripper pre-step: S transitions and the weld wrench on a held
// object; coupling, rod contact, rod step, rigid step; one snapshot and rollback for all of it),
// then events and monitoring. control_step() is the one door for actions: every caller
// (environments, demos, planners, the Python module) gets its element torques clamped to the
// actuation limits there (rod::clamp_to_limits, ArmWorldSettings::limits).
// The "no table" and "no rod contact" arms (the reach environment) are this world configured:
// no add_table(), ArmWorldSettings::rod_contact_enabled = false.
// Reporting, never a crash: a non-finite state throws manisoft::Error naming the step and the rod
// node/element or the rigid body (with its name); objects that leave the table top (centre of mass
// outside its rectangle or below its surface) or the workspace box, and grasp, release and slip
// events, are appended to events(); a fallen object keeps being simulated (the optional floor
// catches it).
// Deterministic: the same calls give bit-identical states (no threads, no unordered containers,
// bodies and geometries visited in index order).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "manisoft/interaction/gripper.hpp"
#include "manisoft/rod/actuation_limits.hpp"
#include "manisoft/interaction/rod_contact.hpp"
#include "manisoft/world/soft_arm_world.hpp"

namespace manisoft::world {

struct ArmWorldSettings {
  rigid::RigidWorldSettings rigid{};
  interaction::ParallelGripperParameters gripper{};
  interaction::ElasticSpringParameters coupling = interaction::ElasticSpringParameters::arm();
  interaction::RodContactParameters rod_contact{};
  bool rod_contact_enabled = true;          ///< false: the rod passes through bodies (free-space arm)
  rod::ActuationLimits<double> limits{};    ///< applied to every control_step's torques
  int substeps_per_control_step = 7;  ///< 714 Hz at dt = 2e-4 s (paper)
  Eigen::Vector3d workspace_lo{-3, -3, -1};
  Eigen::Vector3d workspace_hi{3, 3, 4};
};

/// A table: a static box whose top face is centred at `top_center`, horizontal.
struct TableDesc {
  Eigen::Vector3d top_center{0.4, 0, 0.75};
  double half_x = 0.4, half_y = 0.5;  ///< m, of the top
  double thickness = 0.05;            ///< m (the collision box below the top face)
  double friction = 0.6;
  double rolling_resistance = 1e-3;   ///< m (rigid::RigidBodyDesc::rolling_resistance), also the floor's
  bool add_floor = true;              ///< a static floor at z = 0 catches fallen objects
};

struct WorldEvent {
  enum class Kind { grasped, released, slipped, left_table, left_workspace };
  Kind kind{Kind::grasped};
  long step = 0;
  double time = 0;
  rigid::BodyId body = 0;
  std::string name;
};

inline const char* to_string(WorldEvent::Kind k) {
  switch (k) {
    case WorldEvent::Kind::grasped: return "grasped";
    case WorldEvent::Kind::released: return "released";
    case WorldEvent::Kind::slipped: return "slipped";
    case WorldEvent::Kind::left_table: return "left_table";
    case WorldEvent::Kind::left_workspace: return "left_workspace";
  }
  return "?";
}

/// Default observer of ArmWorld::control_step's substeps: nothing.
struct NoSubstepObserver {
  void operator()() const {}
};

template <typename Rod>
class ArmWorld {
 public:
  using Vec3 = Eigen::Vector3d;
  using Soft = SoftArmWorld<Rod, interaction::ElasticSpring, interaction::RodCapsuleContact, interaction::ParallelGripper>;
  using Torques = Eigen::Matrix<double, Eigen::Dynamic, 3>;

  ArmWorld(Rod rod, const ArmWorldSettings& settings = {})
      : settings_(settings),
        soft_(std::move(rod), settings.rigid, interaction::make_parallel_gripper(settings.gripper), interaction::ElasticSpring(settings.coupling),
              interaction::RodCapsuleContact(settings.rod_contact), interaction::ParallelGripper(settings.gripper)) {
    if (settings_.substeps_per_control_step < 1) {
      manisoft::detail::fail("ArmWorldSettings::substeps_per_control_step = ", settings_.substeps_per_control_step, " must be >= 1");
    }
    settings_.limits.validate();
    soft_.rod_contact().exclude(soft_.end_effector());  // the coupling joins them
    soft_.set_workspace(settings_.workspace_lo, settings_.workspace_hi);
    torques_.setZero(soft_.rod().n_elements(), 3);
  }

  // ---- scene building
  /// Adds the table (and, if asked, a floor at z = 0); returns the table's body id.
  rigid::BodyId add_table(const TableDesc& t) {
    if (has_table_) manisoft::detail::fail("ArmWorld::add_table: the world has a table already");
    manisoft::detail::require_positive("TableDesc half_x", t.half_x);
    manisoft::detail::require_positive("TableDesc half_y", t.half_y);
    manisoft::detail::require_positive("TableDesc thickness", t.thickness);
    if (!t.top_center.allFinite()) manisoft::detail::fail("TableDesc top_center is not finite");
    rigid::RigidBodyDesc d;
    d.shape = geometry::Box<double>{Vec3(t.half_x, t.half_y, 0.5 * t.thickness)};
    d.position = t.top_center - Vec3(0, 0, 0.5 * t.thickness);
    d.is_static = true;
    d.friction = t.friction;
    d.rolling_resistance = t.rolling_resistance;
    d.name = "table";
    table_ = t;
    table_id_ = add_body(d);
    has_table_ = true;
    if (t.add_floor) {
      rigid::RigidBodyDesc f;
      f.shape = geometry::Box<double>{Vec3(4, 4, 0.05)};
      f.position = Vec3(t.top_center.x(), t.top_center.y(), -0.05);
      f.is_static = true;
      f.friction = t.friction;
      f.rolling_resistance = t.rolling_resistance;
      f.name = "floor";
      add_body(f);
    }
    return table_id_;
  }
  /// Adds a static obstacle.
  rigid::BodyId add_obstacle(rigid::RigidBodyDesc d) {
    d.is_static = true;
    return add_body(d);
  }
  /// Adds a dynamic object (monitored: leaving the table or the workspace is reported).
  rigid::BodyId add_object(const rigid::RigidBodyDesc& d) {
    if (d.is_static) manisoft::detail::fail("ArmWorld::add_object: '", d.name, "' is static; use add_obstacle");
    const rigid::BodyId id = add_body(d);
    objects_.push_back(id);
    off_table_.push_back(false);
    outside_.push_back(false);
    return id;
  }

  // ---- stepping
  /// Gripper command S in {0, 1}, effective from the next step.
  void set_gripper(int s) { gripper().command(s); }

  /// One simulation step (dt); on failure everything is as before the step (see SoftArmWorld).
  void step() {
    soft_.step();
    const auto& g = gripper();
    if (g.grasped_now()) record(WorldEvent::Kind::grasped, *g.held());
    if (g.released_now()) record(g.slipped() ? WorldEvent::Kind::slipped : WorldEvent::Kind::released, *g.last_released());
    monitor();
  }
  void step(int count) {
    for (int i = 0; i < count; ++i) step();
  }
  /// One control step: element torques (n x 3, material frame) clamped to the actuation limits,
  /// gripper state S, then substeps_per_control_step substeps, calling `after_substep()` after
  /// each. Returns the number of clamped entries. A torque matrix of the wrong shape or with a
  /// non-finite entry, or an S other than 0 or 1, is refused naming it before anything changes.
  template <typename Matrix, typename AfterSubstep = NoSubstepObserver>
  int control_step(const Matrix& torques, int s, AfterSubstep&& after_substep = {})
    requires requires(Rod& r) { r.template forcing<rod::forcing::ElementTorques>(); }
  {
    if (torques.rows() != torques_.rows() || torques.cols() != 3)
      manisoft::detail::fail("ArmWorld::control_step: torques must be ", torques_.rows(), " x 3, got ", torques.rows(), " x ", torques.cols());
    for (int r = 0; r < torques_.rows(); ++r)
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(double(torques(r, c))))
          manisoft::detail::fail("ArmWorld::control_step: torque entry (", r, ", ", c, ") (element ", r, ", component d", c + 1, ") = ", torques(r, c), " is not finite");
    if (s != 0 && s != 1) manisoft::detail::fail("ArmWorld::control_step: S = ", s, " must be 0 (open) or 1 (closed)");
    torques_ = torques.template cast<double>();
    const int clamped = rod::clamp_to_limits(settings_.limits, torques_);
    soft_.rod().template forcing<rod::forcing::ElementTorques>().set(torques_);
    set_gripper(s);
    for (int i = 0; i < settings_.substeps_per_control_step; ++i) {
      step();
      after_substep();
    }
    return clamped;
  }
  /// The element torques of the last control step, after the limits.
  const Torques& applied_torques() const { return torques_; }

  // ---- access
  Soft& soft() { return soft_; }
  const Soft& soft() const { return soft_; }
  Rod& rod() { return soft_.rod(); }
  const Rod& rod() const { return soft_.rod(); }
  rigid::RigidWorld& rigid() { return soft_.rigid(); }
  const rigid::RigidWorld& rigid() const { return soft_.rigid(); }
  interaction::ParallelGripper& gripper() { return soft_.device(); }
  const interaction::ParallelGripper& gripper() const { return soft_.device(); }
  rigid::BodyId gripper_body() const { return soft_.end_effector(); }
  interaction::RodCapsuleContact& rod_contact() { return soft_.rod_contact(); }
  const interaction::RodCapsuleContact& rod_contact() const { return soft_.rod_contact(); }
  const std::vector<rigid::BodyId>& objects() const { return objects_; }
  const std::vector<WorldEvent>& events() const { return events_; }
  bool has_table() const { return has_table_; }
  rigid::BodyId table() const { return table_id_; }
  const TableDesc& table_desc() const { return table_; }
  const ArmWorldSettings& settings() const { return settings_; }
  long step_count() const { return soft_.step_count(); }
  double time() const { return soft_.time(); }
  /// Whether object `id` is currently counted as off the table (see events()).
  bool is_off_table(rigid::BodyId id) const {
    for (std::size_t i = 0; i < objects_.size(); ++i) {
      if (objects_[i] == id) return off_table_[i];
    }
    manisoft::detail::fail("ArmWorld::is_off_table: body ", id, " is not an object");
  }

 private:
  rigid::BodyId add_body(const rigid::RigidBodyDesc& d) {
    const rigid::BodyId id = soft_.rigid().add_body(d);
    if (!settings_.rod_contact_enabled) soft_.rod_contact().exclude(id);
    return id;
  }

  void record(WorldEvent::Kind kind, rigid::BodyId body) {
    WorldEvent e;
    e.kind = kind;
    e.step = soft_.step_count();
    e.time = soft_.time();
    e.body = body;
    e.name = soft_.rigid().model(body).name;
    events_.push_back(std::move(e));
  }

  void monitor() {
    const auto& rigid = soft_.rigid();
    const auto& outside = soft_.outside_workspace();
    for (std::size_t i = 0; i < objects_.size(); ++i) {
      const rigid::BodyId b = objects_[i];
      if (has_table_) {
        const Vec3 x = rigid.center_of_mass(b);
        const Vec3 d = x - table_.top_center;
        const bool held = gripper().held() && *gripper().held() == b;
        const bool off = !held && (std::abs(d.x()) > table_.half_x || std::abs(d.y()) > table_.half_y || d.z() < 0);
        if (off && !off_table_[i]) record(WorldEvent::Kind::left_table, b);
        off_table_[i] = off;
      }
      const bool out = std::find(outside.begin(), outside.end(), b) != outside.end();
      if (out && !outside_[i]) record(WorldEvent::Kind::left_workspace, b);
      outside_[i] = out;
    }
  }

  ArmWorldSettings settings_;
  Soft soft_;
  Torques torques_;
  TableDesc table_;
  rigid::BodyId table_id_ = 0;
  bool has_table_ = false;
  std::vector<rigid::BodyId> objects_;
  std::vector<bool> off_table_, outside_;
  std::vector<WorldEvent> events_;
};

}  // namespace manisoft::world
