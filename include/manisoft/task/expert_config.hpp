// The expert's configuration (expert.hpp), grouped by the job each setting serves: the timing of
// every path (paths), the approach and grasp (approach), the carry (carry), the lower and place
// (lower), the release (release), the retract (retract), the waits for the arm to settle (settle)
// and the planned lines' checks (checks); and what the phase machine reports (ExpertPhase,
// ExpertEvent). Distances in m, speeds in m/s. for_each_field() lists every setting once, with its
// group, name and range: ExpertConfig::validate() refuses a value out of range naming it
// ("ExpertConfig carry.peak_speed = -1 ..."), and expert_config_json.hpp reads and writes the
// same names.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>

#include "manisoft/core/error.hpp"

namespace manisoft::task {

struct ExpertConfig {
  /// The timing of every path (ModelExecutor::track_line) and when the next one starts.
  struct Paths {
    double peak_speed = 1.5;        ///< m/s, peak end-effector speed of a path's quintic timing (gripper empty)
    double node_speed = 1.5;        ///< m/s, planned peak speed of any rod node (gripper empty)
    double cruise = 0.7;            ///< fraction of a path at constant speed (0: quintic timing; ModelExecutor::track_line)
    int min_segment_steps = 60;     ///< shortest path, control steps
    double start_error = 0.03;      ///< m: a chained path starts once the previous one is this near
    double via_error = 0.05;        ///< m: the same at a leg's arc or via point (the next line starts from the shape target; the arm catches up)
    double arc_inset = 0.03;        ///< m: a straight leg this much nearer the base than its farther end goes round an arc point
    bool ramp_fallback = true;      ///< a refused line may be replaced by a shape ramp
    bool freeze_estimate_in_contact = true;  ///< the executor's stiffness estimate is frozen while the tool may touch things (descend, close, lower, open)
  };
  /// The approach to a grasp, the descent to it and the re-tries of a failed one.
  struct Approach {
    double distance = 0.06;         ///< m: the approach pose this far from the grasp, along the annotation's approach direction
    double tip_clearance = 0.02;    ///< m: a tall object's approach keeps the open fingertips this far above its top until they straddle it
    double via_raise = 0.1;         ///< m: the high variants of a grasp (tried after its others) raise their via points this much
    double tight_clearance = 0.015; ///< m: a grasp is tight when the open fingers clear the object by less on each side: descend to it at tight_peak_speed
    double tight_peak_speed = 0.6;  ///< m/s: peak end-effector speed of the descent to a tight grasp
    double grasp_error = 0.02;      ///< m: a descent that ends farther than this from its grasp pose (a finger on the object) backs off and re-tries
    int max_retries = 1;            ///< re-tries of a move whose grasp failed (missed, blocked or not carriable), each with another grasp
  };
  /// The carry from the grasp to above the place pose.
  struct Carry {
    double height = 0.05;           ///< m: end-effector above the place pose before lowering
    double lift_height = 0.06;      ///< m: straight up from the grasp first (a "via" carry)
    double peak_speed = 1.5;        ///< m/s, peak end-effector speed while an object is held (its acceleration bounded by grip_share)
    double node_speed = 1.5;        ///< m/s, planned peak speed of any rod node while an object is held
    double grip_share = 0.45;       ///< a held line's planned peak acceleration at most this share of what the grip holds (max_hold_force / mass; 0: not bounded): a short lift at the carry's full speed can accelerate a tall object past what the grip holds
    double settle_speed = 0.1;      ///< m/s: lower only once the arm's tip is slower at the end of the carry (0: at once)
  };
  /// The lower onto the support and where the object is let go.
  struct Lower {
    double place_clearance = 0.008;  ///< m: the object's bottom above its support when released
    double peak_speed = 0.3;         ///< m/s: peak end-effector speed of the lower line
    double slow_distance = 0.03;     ///< m: a lower line longer than twice this runs at the carry's speed until this far above its end (0: all slow)
    double contact_depth = 0.001;    ///< m: a tall object is lowered until its support carries it: its lower line ends this far below its support (deeper presses it on, and it rocks on its base after the release)
    double stack_finger_clearance = 0.0;  ///< m: STK: the lower stops with the fingertips this far above the item below's top (lower_goal)
  };
  /// The release of a tall object.
  struct Release {
    double tall_ratio = 1.2;         ///< an object is tall (settle_speed) above this height / width
    double settle_speed = 0.05;      ///< m/s: once the support carries a tall object, stop and open only when the arm's tip is slower (0: open at once)
    double lift = 0.0;               ///< m: the stop above where the arm is (settle_speed)
    double clearance = 0.01;         ///< m: the retract from a tall object waits until the opening fingers clear it by this much on each side (or are fully open)
  };
  /// The retract after every release.
  struct Retract {
    double height = 0.06;            ///< m: up after every release (at least)
    double finger_clearance = 0.02;  ///< m: and until the fingertips are this far above the released object's top
    double peak_speed = 0.9;         ///< m/s: peak end-effector speed of the retract
  };
  /// The waits before closing and opening.
  struct Settle {
    double speed = 0.15;             ///< m/s: close / open only when the arm's tip is slower
    double error = 0.01;             ///< m: and the end-effector this near its pose
    int max_steps = 200;             ///< longest wait for settling (then act anyway)
  };
  /// The checks of a planned line (expert_checks.hpp).
  struct Checks {
    double table_clearance = 0.03;   ///< m: every rod node of a waypoint shape above the table top
    double arm_clearance = 0.01;     ///< m: the rod's surface clear of the other objects' and obstacles' boxes along planned lines
    double held_clearance = 0.01;    ///< m: the held object's and the open gripper's boxes clear of theirs along the carry
    bool objects = true;             ///< false: lines are not checked against objects and obstacles (for measuring the check)
  };

  Paths paths;
  Approach approach;
  Carry carry;
  Lower lower;
  Release release;
  Retract retract;
  Settle settle;
  Checks checks;

  /// Refuses a value out of its range, naming the field ("ExpertConfig carry.peak_speed = -1 ...").
  void validate() const;
};

/// The range of a setting: finite, from `low` (excluded when `open`) to `high`.
struct ExpertLimit {
  double low = -std::numeric_limits<double>::infinity();
  bool open = false;
  double high = std::numeric_limits<double>::infinity();

  bool holds(double v) const { return std::isfinite(v) && (open ? v > low : v >= low) && v <= high; }
  std::string describe() const {
    std::ostringstream s;
    s << (open ? "> " : ">= ") << low;
    if (std::isfinite(high)) s << " and <= " << high;
    return s.str();
  }
};

/// Calls f(group, name, value, limit) for every setting of `c` (an ExpertConfig, const or not);
/// a flag's limit is unused.
template <typename Config, typename F>
void for_each_field(Config& c, F&& f) {
  constexpr ExpertLimit positive{0, true}, non_negative{0, false}, any{};
  f("paths", "peak_speed", c.paths.peak_speed, positive);
  f("paths", "node_speed", c.paths.node_speed, positive);
  f("paths", "cruise", c.paths.cruise, ExpertLimit{0, false, 0.95});
  f("paths", "min_segment_steps", c.paths.min_segment_steps, ExpertLimit{1, false});
  f("paths", "start_error", c.paths.start_error, positive);
  f("paths", "via_error", c.paths.via_error, positive);
  f("paths", "arc_inset", c.paths.arc_inset, non_negative);
  f("paths", "ramp_fallback", c.paths.ramp_fallback, any);
  f("paths", "freeze_estimate_in_contact", c.paths.freeze_estimate_in_contact, any);
  f("approach", "distance", c.approach.distance, positive);
  f("approach", "tip_clearance", c.approach.tip_clearance, non_negative);
  f("approach", "via_raise", c.approach.via_raise, non_negative);
  f("approach", "tight_clearance", c.approach.tight_clearance, non_negative);
  f("approach", "tight_peak_speed", c.approach.tight_peak_speed, positive);
  f("approach", "grasp_error", c.approach.grasp_error, positive);
  f("approach", "max_retries", c.approach.max_retries, non_negative);
  f("carry", "height", c.carry.height, non_negative);
  f("carry", "lift_height", c.carry.lift_height, non_negative);
  f("carry", "peak_speed", c.carry.peak_speed, positive);
  f("carry", "node_speed", c.carry.node_speed, positive);
  f("carry", "grip_share", c.carry.grip_share, non_negative);
  f("carry", "settle_speed", c.carry.settle_speed, non_negative);
  f("lower", "place_clearance", c.lower.place_clearance, non_negative);
  f("lower", "peak_speed", c.lower.peak_speed, positive);
  f("lower", "slow_distance", c.lower.slow_distance, non_negative);
  f("lower", "contact_depth", c.lower.contact_depth, non_negative);
  f("lower", "stack_finger_clearance", c.lower.stack_finger_clearance, non_negative);
  f("release", "tall_ratio", c.release.tall_ratio, positive);
  f("release", "settle_speed", c.release.settle_speed, non_negative);
  f("release", "lift", c.release.lift, non_negative);
  f("release", "clearance", c.release.clearance, non_negative);
  f("retract", "height", c.retract.height, non_negative);
  f("retract", "finger_clearance", c.retract.finger_clearance, non_negative);
  f("retract", "peak_speed", c.retract.peak_speed, positive);
  f("settle", "speed", c.settle.speed, positive);
  f("settle", "error", c.settle.error, positive);
  f("settle", "max_steps", c.settle.max_steps, non_negative);
  f("checks", "table_clearance", c.checks.table_clearance, non_negative);
  f("checks", "arm_clearance", c.checks.arm_clearance, non_negative);
  f("checks", "held_clearance", c.checks.held_clearance, non_negative);
  f("checks", "objects", c.checks.objects, any);
}

inline void ExpertConfig::validate() const {
  for_each_field(*this, [](std::string_view group, std::string_view name, const auto& value, const ExpertLimit& limit) {
    if constexpr (!std::is_same_v<std::decay_t<decltype(value)>, bool>) {
      if (!limit.holds(static_cast<double>(value)))
        manisoft::detail::fail("ExpertConfig ", group, '.', name, " = ", value, " is invalid: it must be finite and ", limit.describe());
    }
  });
}

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
