// The expert's choice of grasp for a move (paper section 3.4). The candidates: each of the asset's
// annotated grasps, also turned half a turn about the fingers' axis (the parallel gripper is
// symmetric) and about the object's axis as its symmetry allows (round: eighth turns, square:
// quarter turns), each with seven leg variants (the approach and the carry each direct or "via",
// and the via ones again raised by approach.via_raise: expert_legs.hpp). Their cost: least turning
// from the home pose (the grasp's and the place's end-effector poses) first, then the fewest lines;
// approaches that would sweep the open fingers into a tall object last. The chosen one is the
// cheapest whose whole sequence passes the checks (expert_checks.hpp): first with straight lines
// only, then (not on a re-try) with refused lines repaired by shape ramps. No detour around an
// obstacle is planned: a move with no clear candidate is given up. Grasps a re-try left out
// (excluded_) are not candidates.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "manisoft/task/expert_checks.hpp"

namespace manisoft::task::detail {

/// The expert's grasp candidates and their check (a base of Expert).
class GraspChoice : protected ExpertChecks {
 protected:
  GraspChoice(const TaskEnv& env, const ExpertConfig& config) : ExpertChecks(env, config) { excluded_.reserve(8); }

  /// A grasp candidate of a move and its cost (least turning first, then the fewest lines).
  struct Candidate {
    double cost;
    Plan plan;
  };
  /// Every grasp candidate of putting `object` at `target`, cheapest first: each annotated grasp
  /// turned about the object's axis as its symmetry allows (round: eighth turns, square: quarter
  /// turns) and half a turn about the fingers' axis (the parallel gripper), each with seven leg
  /// variants, their legs starting from the end-effector pose `from`; grasps a re-try left out
  /// are not among them.
  std::vector<Candidate> grasp_candidates(int object, const Pose& target, const Support& support, const Pose& from) const {
    const auto& a = asset_of(object);
    const Pose now = state_of(object).pose;
    std::vector<Candidate> candidates;
    const scene::Symmetry sym = scene::asset_symmetry(a);
    const int object_turns = sym.kind == scene::Symmetry::Kind::axial ? 8 : sym.kind == scene::Symmetry::Kind::discrete ? std::max(1, sym.order) : 1;
    for (const auto& g : a.grasps) {
      for (int t = 0; t < object_turns; ++t) {
        Pose about_axis;
        about_axis.rotation = Eigen::AngleAxisd(2 * std::numbers::pi * t / object_turns, Vec3::UnitZ()).toRotationMatrix();
        for (int flip = 0; flip < 2; ++flip) {
          Pose half;
          half.rotation = Eigen::AngleAxisd(flip * std::numbers::pi, Vec3::UnitZ()).toRotationMatrix();
          for (int variant = 0; variant < 8; ++variant) {
            if (variant == 4) continue;  // raised with no via point: the same as variant 0
            Plan p;
            p.object = object;
            p.object_target = target;
            p.width = g.width;
            p.grasp = now * about_axis * g.grasp * half;
            if (excluded(now, p.grasp)) continue;
            p.place = target * now.inverse() * p.grasp;
            sink_into_container(p, support);
            p.via_approach = variant & 1;
            p.via_carry = variant & 2;
            p.raise = variant & 4 ? config_.approach.via_raise : 0.0;
            const bool clear = set_approach_leg(p, now * about_axis * approach_pose(g) * half, from);
            set_carry_leg(p);
            // least turning first, then the fewest lines
            // (approaches that would sweep the fingers into a tall object last)
            const double cost = std::max(turn_from_home(p.grasp), turn_from_home(p.place)) + 1e-3 * variant + (clear ? 0.0 : 10.0);
            candidates.push_back({cost, p});
          }
        }
      }
    }
    std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) { return x.cost < y.cost; });
    return candidates;
  }
  /// Checks candidate plan p of move k on planner_ from `executor`'s shape target: approach,
  /// grasp, carry (holding the object), place; `plan`: the moved object and whether refused lines
  /// may be repaired. False (the first refusal noted in plan_refusal_) when a line is refused.
  bool check_candidate(Plan& p, int k, const Executor& executor, const LinePlan& plan) {
    const auto& a = asset_of(p.object);
    const Pose now = state_of(p.object).pose;
    planner_ = executor;
    planner_.complete_path();
    const char* why = "";
    const char* where = "";
    bool ok = check_leg(p.approach_leg, plan, why);
    if (!ok) where = "approach";
    if (ok && !(ok = check_line(p.grasp, plan, why))) where = "grasp";
    if (ok) {
      planner_.set_payload(a.mass, p.grasp.rotation.transpose() * (now.act(a.center_of_mass) - p.grasp.translation));
      if (!(ok = check_carry_leg(p, p.grasp, now, support_of(k).object, plan, why))) where = "carry";
    }
    if (ok && !(ok = check_line(p.place, plan, why))) where = "place";
    if (!ok && plan_refusal_.empty()) plan_refusal_ = std::string(where) + ": " + why;
    return ok;
  }
  /// Whether grasp g (end-effector pose, the object at `object`) is one a re-try left out.
  bool excluded(const Pose& object, const Pose& g) const {
    for (const Pose& e : excluded_) {
      const Pose d = object.inverse() * g;
      if ((d.translation - e.translation).norm() < 0.01 && Eigen::AngleAxisd(d.rotation * e.rotation.transpose()).angle() < 0.2) return true;
    }
    return false;
  }

  std::vector<Pose> excluded_;  ///< grasps (in the object's frame) re-tries of this move leave out
  std::string plan_refusal_;  ///< why the least-turning grasp candidate was refused
};

}  // namespace manisoft::task::detail
