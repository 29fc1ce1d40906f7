// The expert's configuration (expert.hpp): the heights, clearances, speeds and waits of its
// moves, and what its phase machine reports (ExpertPhase, ExpertEvent). Distances in m, speeds
// in m/s; ExpertConfig::validate() refuses a value out of its range, naming the field.
#pragma once

#include <Eigen/Core>

#include <string>
#include <string_view>
#include <utility>

#include "manisoft/core/error.hpp"

namespace manisoft::task {

struct ExpertConfig {
  double carry_height = 0.05;       ///< m: end-effector above the place pose before lowering
  double lift_height = 0.06;        ///< m: straight up from the grasp first (a "via" carry)
  double via_raise = 0.1;           ///< m: the high variants of a grasp (tried after its others) raise their via points this much
  double place_clearance = 0.008;   ///< m: the object's bottom above its support when released
  double retract_height = 0.06;     ///< m: up after every release (at least)
  double finger_clearance = 0.02;   ///< m: and until the fingertips are this far above the released object's top
  double stack_finger_clearance = 0.0;  ///< m: STK: the lower stops with the fingertips this far above the item below's top (lower_goal)
  double path_peak_speed = 1.5;     ///< m/s, peak end-effector speed of a path's quintic timing (gripper empty)
  double max_node_speed = 1.5;      ///< m/s, planned peak speed of any rod node (gripper empty)
  double carry_peak_speed = 1.5;    ///< m/s, the same while an object is held (its acceleration bounded by carry_grip_share)
  double carry_node_speed = 1.5;    ///< m/s
  double carry_grip_share = 0.45;   ///< a held line's planned peak acceleration at most this share of what the grip holds (max_hold_force / mass; 0: not bounded): a short lift at the carry's full speed can accelerate a tall object past what the grip holds
  double path_cruise = 0.7;         ///< fraction of a path at constant speed (0: quintic timing; ModelExecutor::track_line)
  int min_segment_steps = 60;       ///< shortest path, control steps
  double settle_speed = 0.15;       ///< m/s: close / open only when the arm's tip is slower
  double settle_error = 0.01;       ///< m: and the end-effector this near its pose
  int max_settle_steps = 200;       ///< longest wait for settling (then act anyway)
  double release_settle_speed = 0.05;  ///< m/s: once the support carries a tall object, stop and open only when the arm's tip is slower (0: open at once)
  double tall_ratio = 1.2;          ///< an object is tall (release_settle_speed) above this height / width
  double release_lift = 0.0;        ///< m: the stop above where the arm is (release_settle_speed)
  double release_clearance = 0.01;  ///< m: the retract from a tall object waits until the opening fingers clear it by this much on each side (or are fully open)
  double contact_depth = 0.001;     ///< m: a tall object is lowered until its support carries it: its lower line ends this far below its support (deeper presses it on, and it rocks on its base after the release)
  double retract_peak_speed = 0.9;  ///< m/s: peak end-effector speed of the retract after a release
  double lower_peak_speed = 0.3;    ///< m/s: peak end-effector speed of the lower line
  double slow_lower = 0.03;         ///< m: a lower line longer than twice this runs at the carry's speed until this far above its end (0: all slow)
  double approach_tip_clearance = 0.02;  ///< m: a tall object's approach keeps the open fingertips this far above its top until they straddle it
  double carry_settle_speed = 0.1;  ///< m/s: lower only once the arm's tip is slower at the end of the carry (0: at once)
  double tight_clearance = 0.015;   ///< m: a grasp is tight when the open fingers clear the object by less on each side: descend to it at tight_peak_speed
  double tight_peak_speed = 0.6;    ///< m/s: peak end-effector speed of the descent to a tight grasp
  double start_error = 0.03;       ///< m: a chained path starts once the previous one is this near
  double via_error = 0.05;          ///< m: the same at a leg's arc or via point (the next line starts from the shape target; the arm catches up)
  double table_clearance = 0.03;    ///< m: every rod node of a waypoint shape above the table top
  double arm_clearance = 0.01;      ///< m: the rod's surface clear of the other objects' and obstacles' boxes along planned lines
  double held_clearance = 0.01;     ///< m: the held object's and the open gripper's boxes clear of theirs along the carry
  bool check_arm_clearance = true;  ///< false: lines are not checked against objects and obstacles (for measuring the check)
  double arc_inset = 0.03;          ///< m: a straight leg this much nearer the base than its farther end goes round an arc point
  int max_retries = 1;              ///< re-tries of a move whose grasp failed (missed, blocked or not carriable), each with another grasp
  double grasp_error = 0.02;        ///< m: a descent that ends farther than this from its grasp pose (a finger on the object) backs off and re-tries
  double approach_distance = 0.06;  ///< m: the approach pose this far from the grasp, along the annotation's approach direction
  bool ramp_fallback = true;        ///< a refused line may be replaced by a shape ramp
  bool freeze_estimate_in_contact = true;  ///< the executor's stiffness estimate is frozen while the tool may touch things (descend, close, lower, open)

  /// Refuses a value out of its range, naming the field (speeds and errors > 0, distances >= 0).
  void validate() const {
    using manisoft::detail::require_non_negative;
    using manisoft::detail::require_positive;
    for (const auto& [name, v] : {std::pair{"carry_height", carry_height}, {"lift_height", lift_height}, {"via_raise", via_raise},
                                  {"place_clearance", place_clearance}, {"retract_height", retract_height},
                                  {"finger_clearance", finger_clearance}, {"stack_finger_clearance", stack_finger_clearance},
                                  {"carry_grip_share", carry_grip_share}, {"release_settle_speed", release_settle_speed},
                                  {"release_lift", release_lift}, {"release_clearance", release_clearance}, {"contact_depth", contact_depth}, {"slow_lower", slow_lower},
                                  {"approach_tip_clearance", approach_tip_clearance}, {"carry_settle_speed", carry_settle_speed},
                                  {"tight_clearance", tight_clearance}, {"table_clearance", table_clearance},
                                  {"arm_clearance", arm_clearance}, {"held_clearance", held_clearance}, {"arc_inset", arc_inset}}) {
      require_non_negative((std::string("ExpertConfig ") + name).c_str(), v);
    }
    for (const auto& [name, v] : {std::pair{"path_peak_speed", path_peak_speed}, {"max_node_speed", max_node_speed},
                                  {"carry_peak_speed", carry_peak_speed}, {"carry_node_speed", carry_node_speed},
                                  {"settle_speed", settle_speed}, {"settle_error", settle_error}, {"tall_ratio", tall_ratio},
                                  {"retract_peak_speed", retract_peak_speed}, {"lower_peak_speed", lower_peak_speed},
                                  {"tight_peak_speed", tight_peak_speed}, {"start_error", start_error}, {"via_error", via_error},
                                  {"grasp_error", grasp_error}, {"approach_distance", approach_distance}}) {
      require_positive((std::string("ExpertConfig ") + name).c_str(), v);
    }
    if (!(path_cruise >= 0 && path_cruise <= 0.95)) manisoft::detail::fail("ExpertConfig path_cruise = ", path_cruise, " is invalid: it must be in [0, 0.95]");
    if (min_segment_steps < 1 || max_settle_steps < 0 || max_retries < 0) {
      manisoft::detail::fail("ExpertConfig min_segment_steps = ", min_segment_steps, " (>= 1), max_settle_steps = ", max_settle_steps,
                             " (>= 0), max_retries = ", max_retries, " (>= 0): out of range");
    }
  }
};

/// What the expert is doing.
enum class ExpertPhase { approach, descend, close, carry, lower, open, retract, idle, failed };

inline std::string_view to_string(ExpertPhase p) {
  switch (p) {
    case ExpertPhase::approach: return "approach";
    case ExpertPhase::descend: return "descend";
    case ExpertPhase::close: return "close";
    case ExpertPhase::carry: return "carry";
    case ExpertPhase::lower: return "lower";
    case ExpertPhase::open: return "open";
    case ExpertPhase::retract: return "retract";
    case ExpertPhase::idle: return "idle";
    case ExpertPhase::failed: return "failed";
  }
  return "?";
}

/// A waypoint reached (or a phase entered) at a control step.
struct ExpertEvent {
  long step = 0;
  int move = 0;
  ExpertPhase phase = ExpertPhase::approach;
  Eigen::Vector3d position{Eigen::Vector3d::Zero()};  ///< end-effector position when it happened
};

}  // namespace manisoft::task
