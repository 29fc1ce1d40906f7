// Scene samplers of the five tasks in the clean and randomized settings (paper sections 3.2,
// 3.3 and 3.5, figure 4c):
//  COLL  a designated object of one of the paper's 13 categories + a container (a basket);
//  ALN   a bottle, shoe or candle stick + a goal pose (upright, a yaw) on the table;
//  STK   2-4 bowls or plates of graded size (strictly decreasing width) within stk_spread of the
//        largest (a set of dishes), goal largest first;
//  ARR   one relation, each kind equally often (left_of, right_of, in_front_of, behind, next_to with
//        2-3 objects; between, in_a_row with 3) among Rubik's cube / bottle / pen cup / shoe, and a
//        free spot for it;
//  OVR   a bottle or candle stick + a goal marker (upright, the object's yaw) on the table
//        at most ovr_max_goal_distance away, with a tall obstacle (ovr_obstacle_categories,
//        ovr_min_obstacle_height to ovr_max_obstacle_height) standing halfway between them,
//        footprints apart, and out of the way from the arm's home to the object (home_keepout).
// clean: only the task's objects, canonical appearance and lighting, upright at yaw 0, positions
// uniform over the reachable area (ReachBand at each object's grasp height), so they spread
// evenly over the reachable table area; randomized: also 3-10 obstacles anywhere on the table,
// random yaws, table texture and colours, lighting intensity, colour and direction, object colours.
// Footprints (circles around the bounding boxes; graspable objects keep the gripper's palm free
// around them) never overlap. Each draw is checked by SceneValidator; a failing draw is redrawn
// with the next attempt's engine seed (scene_random.hpp), and the redraws are counted in
// SceneSpec::sampling. Deterministic: the same request gives the same scene, bit for bit, from g++
// and clang++ (never two draws in one expression: argument evaluation order is unspecified).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "manisoft/core/error.hpp"
#include "manisoft/geometry/spatial_relation.hpp"
#include "manisoft/scene/asset_library.hpp"
#include "manisoft/scene/reach_map.hpp"
#include "manisoft/scene/scene_instructions.hpp"
#include "manisoft/scene/scene_random.hpp"
#include "manisoft/scene/scene_spec.hpp"
#include "manisoft/scene/scene_validation.hpp"

namespace manisoft::scene {

/// The categories each task draws from (the paper's lists).
inline const std::vector<std::string>& coll_categories() {
  static const std::vector<std::string> c{"bottle", "pill_bottle", "can", "cup", "sand_clock", "shoe", "candle_stick",
                                          "box_drink", "kettle", "pen_cup", "sauce_can", "rubiks_cube", "trophy"};
  return c;
}
inline const std::vector<std::string>& coll_containers() {
  static const std::vector<std::string> c{"basket"};
  return c;
}
inline const std::vector<std::string>& aln_categories() {
  static const std::vector<std::string> c{"bottle", "shoe", "candle_stick"};
  return c;
}
/// OVR's objects: ALN's upright round ones (a shoe, held at its side, slips out of the grip on
/// the long high carry).
inline const std::vector<std::string>& ovr_categories() {
  static const std::vector<std::string> c{"bottle", "candle_stick"};
  return c;
}
/// OVR's obstacle that stands between the object and its goal: tall, footprints of about 0.1-0.2 m.
inline const std::vector<std::string>& ovr_obstacle_categories() {
  static const std::vector<std::string> c{"vase", "thermos", "pitcher", "speaker", "watering_can"};
  return c;
}
inline const std::vector<std::string>& stk_categories() {
  static const std::vector<std::string> c{"bowl", "plate"};
  return c;
}
inline const std::vector<std::string>& arr_categories() {
  static const std::vector<std::string> c{"rubiks_cube", "bottle", "pen_cup", "shoe"};
  return c;
}

struct SamplerSettings {
  int max_attempts = 200;           ///< draws before giving up (an error naming the request)
  int ovr_max_attempts = 2000;      ///< the same for OVR, whose layout (goal, obstacle between, the way from home) rejects most draws
  int placement_tries = 200;        ///< rejection-sampling tries per placement
  double gap = 0.02;                ///< m between footprints
  double gripper_keepout = 0.08;    ///< m: footprint radius at least this around objects to grasp
  double table_margin = 0.02;       ///< m from the table edges
  double min_goal_distance = 0.12;  ///< m: an ALN goal / ARR spot this far from the start at least
  double relation_distance = 0.15;  ///< m between an ARR object and its reference
  double fit_clearance = 0.004;     ///< m: a COLL object is this much narrower than the opening
  double stk_spread = 0.2;          ///< m: STK items lie within this distance of the bottom one (a set of dishes; at 0.3 a stack of three often outlasts the horizon)
  geometry::RelationTolerances relations;  ///< ARR: the success predicate's margins
  double relation_margin = 0.02;    ///< m: the ARR spot holds with margins this much tighter, the start fails with them this much wider
  int min_obstacles = 3, max_obstacles = 10;
  /// OVR: the obstacle between is at least this tall (above the table top), well over the
  /// expert's carry.lift_height with its clearances, so a carry straight across would hit it, and at
  /// most ovr_max_obstacle_height (the arm's reach above it with the object held).
  double ovr_min_obstacle_height = 0.15;  ///< m
  double ovr_max_obstacle_height = 0.25;  ///< m
  double ovr_max_goal_distance = 0.5;     ///< m from the object's start (longer carries outlast the horizon)
  /// The open gripper at the arm's home pose (task::TaskEnvConfig::home: grasp centre above
  /// (0.50, 0), fingertips 0.095 m above the table top): an object or obstacle taller than
  /// home_clear_height keeps its footprint home_keepout (the gripper's half diagonal and a margin)
  /// from home_xy, so the fingers do not start in it.
  Eigen::Vector2d home_xy{0.50, 0.0};
  double home_clear_height = 0.09;  ///< m above the table top
  double home_keepout = 0.09;       ///< m
  ReachBand band;
  ValidationSettings validation;
};

struct SampleRequest {
  Task task = Task::coll;
  Setting setting = Setting::clean;
  Split split = Split::train;
  std::uint64_t index = 0;
  std::uint64_t seed = 0;
};

class SceneSampler {
 public:
  /// `language`: the instruction templates and descriptions (language::Library::load_default():
  /// the shipped data files).
  explicit SceneSampler(SamplerSettings settings = {}, language::Library language = language::Library::load_default())
      : settings_(settings), validator_(library_, settings.validation), language_(std::move(language)) {}
  SceneSampler(const SceneSampler&) = delete;
  SceneSampler& operator=(const SceneSampler&) = delete;

  const AssetLibrary& library() const { return library_; }
  SceneValidator& validator() { return validator_; }
  const SamplerSettings& settings() const { return settings_; }

  /// The scene of `request`: the first valid draw whose goal objects can all be named uniquely,
  /// with its instructions (scene_instructions.hpp); SceneSpec::sampling counts the redraws.
  SceneSpec sample(const SampleRequest& q) {
    std::vector<std::string> rejections;
    const int attempts = q.task == Task::ovr ? settings_.ovr_max_attempts : settings_.max_attempts;
    for (int attempt = 0; attempt < attempts; ++attempt) {
      const std::uint64_t es = engine_seed(q.split, q.task, q.setting, q.index, q.seed, attempt);
      std::optional<SceneSpec> s = draw(q, es);
      std::string why = "placement failed";
      if (s) {
        const ValidationResult v = validator_.check(*s);
        if (!v.valid) {
          why = v.reason;
        } else if (!describe(*s, library_, language_, es)) {
          why = "ambiguous: a goal object has no unique referring expression";
        } else {
          s->sampling.engine_seed = es;
          s->sampling.redraws = attempt;
          s->sampling.rejections = rejections;
          return *std::move(s);
        }
      }
      rejections.push_back(why.substr(0, why.find(':')));
    }
    manisoft::detail::fail("SceneSampler: no valid ", to_string(q.task), " ", to_string(q.setting), " scene for index ", q.index, ", seed ", q.seed,
                           " in ", attempts, " draws");
  }

  /// One unchecked draw with engine seed `es` (nullopt when a placement found no free spot).
  std::optional<SceneSpec> draw(const SampleRequest& q, std::uint64_t es) {
    Draw d(es);
    SceneSpec s;
    s.task = q.task;
    s.setting = q.setting;
    s.split = q.split;
    s.index = q.index;
    s.seed = q.seed;
    discs_.clear();
    const bool rnd = q.setting == Setting::randomized;
    if (rnd) randomize_looks(s, d);
    bool ok = false;
    switch (q.task) {
      case Task::coll: ok = draw_coll(s, d); break;
      case Task::aln: ok = draw_aln(s, d); break;
      case Task::stk: ok = draw_stk(s, d); break;
      case Task::arr: ok = draw_arr(s, d); break;
      case Task::ovr: ok = draw_ovr(s, d); break;
    }
    if (!ok) return std::nullopt;
    if (rnd && !add_obstacles(s, d)) return std::nullopt;
    return s;
  }

 private:
  struct Disc {
    Eigen::Vector2d c;
    double r;
  };

  const assets::Asset& pick_instance(Draw& d, const std::string& category) {
    const auto v = library_.category(category);
    return *d.pick(v);
  }
  double grasp_height(const assets::Asset& a) const { return a.grasps.empty() ? asset_height(a) : a.grasps.front().grasp.translation.z(); }
  double keepout(const assets::Asset& a, bool grasped) const {
    return grasped ? std::max(footprint_radius(a), settings_.gripper_keepout) : footprint_radius(a);
  }
  bool on_table(const SceneSpec& s, const Eigen::Vector2d& p, double r) const {
    const Eigen::Vector2d c = s.table.top_center.head<2>();
    return std::abs(p.x() - c.x()) + r + settings_.table_margin <= s.table.half_x && std::abs(p.y() - c.y()) + r + settings_.table_margin <= s.table.half_y;
  }
  bool free(const Eigen::Vector2d& p, double r, int ignore = -1) const {
    for (std::size_t i = 0; i < discs_.size(); ++i)
      if (static_cast<int>(i) != ignore && (discs_[i].c - p).norm() < discs_[i].r + r + settings_.gap) return false;
    return true;
  }
  /// Whether a footprint of radius r at p for something `height` tall leaves the home gripper free
  /// (SamplerSettings::home_keepout).
  bool clear_of_home(const Eigen::Vector2d& p, double r, double height) const {
    return height <= settings_.home_clear_height || (p - settings_.home_xy).norm() >= r + settings_.home_keepout;
  }
  /// A free point of the reachable area (ReachBand) at grasp height h for a footprint of radius
  /// r of something `height` tall (clear_of_home): uniform over the table (or over the disc of
  /// radius `spread` about `near` when given), kept when inside the band (rejection sampling).
  std::optional<Eigen::Vector2d> reachable_spot(const SceneSpec& s, Draw& d, double h, double r, double height = 0,
                                                const Eigen::Vector2d* near = nullptr, double spread = 0) {
    const auto& b = settings_.band;
    const Eigen::Vector2d c = near ? *near : s.table.top_center.head<2>();
    const double hx = near ? spread : s.table.half_x, hy = near ? spread : s.table.half_y;
    for (int t = 0; t < settings_.placement_tries; ++t) {
      const double px = d.uniform(c.x() - hx, c.x() + hx);  // one draw per statement: the
      const double py = d.uniform(c.y() - hy, c.y() + hy);  // order of arguments is unspecified
      const Eigen::Vector2d p(px, py);
      if (near && (p - c).norm() > spread) continue;
      if (b.contains(p, h) && on_table(s, p, r) && free(p, r) && clear_of_home(p, r, height)) return p;
    }
    return std::nullopt;
  }
  double draw_yaw(const assets::Asset& a, bool rnd, Draw& d) const {
    if (!rnd) return 0.0;
    return asset_symmetry(a).kind == Symmetry::Kind::axial ? d.uniform(-3.14159265358979323846, 3.14159265358979323846)
                                                            : d.uniform(-0.25 * 3.14159265358979323846, 0.25 * 3.14159265358979323846);
  }
  static math::Pose<double> upright(const assets::Asset& a, const Eigen::Vector2d& p, double top, double yaw) {
    math::Pose<double> pose;
    pose.rotation = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * a.resting_poses.front().orientation.toRotationMatrix();
    pose.translation = Eigen::Vector3d(p.x(), p.y(), top + a.resting_poses.front().height);
    return pose;
  }
  /// Places asset `a` in the reachable band at height h (within `spread` of `near` when given);
  /// returns its object index or -1.
  int place_object(SceneSpec& s, Draw& d, const assets::Asset& a, double h, bool grasped, const Eigen::Vector2d* near = nullptr,
                   double spread = 0) {
    const double r = keepout(a, grasped);
    const auto p = reachable_spot(s, d, h, r, asset_height(a), near, spread);
    if (!p) return -1;
    PlacedAsset o;
    o.asset_id = a.id;
    o.pose = upright(a, *p, s.table.top_center.z(), draw_yaw(a, s.setting == Setting::randomized, d));
    if (s.setting == Setting::randomized && d.chance(0.5)) recolor(o.appearance, d);
    s.objects.push_back(o);
    discs_.push_back({*p, r});
    return static_cast<int>(s.objects.size()) - 1;
  }

  static void recolor(Appearance& ap, Draw& d) {
    const auto& pal = assets::catalog_detail::palette();
    const auto& c = d.pick(pal);
    ap.override_color = true;
    ap.color = Eigen::Vector3d(c.r, c.g, c.b);
    ap.color_name = c.name;
    static const std::array<render::TextureKind, 3> tex{render::TextureKind::none, render::TextureKind::noise, render::TextureKind::fabric};
    ap.texture = d.pick(tex);
  }

  void randomize_looks(SceneSpec& s, Draw& d) {
    static const std::array<render::TextureKind, 5> tex{render::TextureKind::wood, render::TextureKind::marble, render::TextureKind::fabric,
                                                         render::TextureKind::checker, render::TextureKind::noise};
    s.table.texture = d.pick(tex);
    // one draw per statement (the evaluation order of arguments differs between compilers)
    s.table.color.x() = d.uniform(0.25, 0.85);
    s.table.color.y() = d.uniform(0.2, 0.8);
    s.table.color.z() = d.uniform(0.15, 0.75);
    s.table.secondary_color = s.table.color * d.uniform(0.4, 0.8);
    s.table.texture_scale = d.uniform(4.0, 14.0);
    s.lighting.intensity = d.uniform(0.6, 1.4);
    for (int i = 0; i < 3; ++i) s.lighting.color[i] = d.uniform(0.8, 1.0);
    s.lighting.direction.x() = d.uniform(-0.6, 0.6);
    s.lighting.direction.y() = d.uniform(-0.6, 0.6);
    s.lighting.direction.z() = -1.0;
    s.lighting.ambient_intensity = d.uniform(0.25, 0.45);
  }

  /// Places 3-10 obstacles (after those the task placed); false when fewer than the drawn count
  /// found room.
  bool add_obstacles(SceneSpec& s, Draw& d) {
    const int n = d.integer(settings_.min_obstacles, settings_.max_obstacles);
    const auto placed_before = static_cast<int>(s.obstacles.size());
    const auto& all = library_.obstacles();
    const double top = s.table.top_center.z();
    for (int k = 0; k < n; ++k) {
      for (int t = 0; t < settings_.placement_tries; ++t) {
        const assets::Asset& a = all[static_cast<std::size_t>(d.integer(0, static_cast<int>(all.size()) - 1))];
        const double r = footprint_radius(a);
        const double px = d.uniform(s.table.top_center.x() - s.table.half_x, s.table.top_center.x() + s.table.half_x);
        const double py = d.uniform(s.table.top_center.y() - s.table.half_y, s.table.top_center.y() + s.table.half_y);
        const Eigen::Vector2d p(px, py);
        if (!on_table(s, p, r) || !free(p, r) || !clear_of_home(p, r, asset_height(a))) continue;
        PlacedAsset o;
        o.asset_id = a.id;
        o.pose = upright(a, p, top, d.uniform(-3.14159265358979323846, 3.14159265358979323846));
        if (d.chance(0.5)) recolor(o.appearance, d);
        s.obstacles.push_back(o);
        discs_.push_back({p, r});
        break;
      }
    }
    return static_cast<int>(s.obstacles.size()) - placed_before == n;
  }

  /// Whether `obj` fits into `container` with `fit_clearance` to spare: it stands on the floor
  /// inside the COLL predicate's inner volume with its centre of mass below the rim. Square
  /// receptacles (a basket's straight walls): its larger side within the opening's smaller side;
  /// round ones: its footprint circle within the inner radius (the narrowest, at the floor: a
  /// bowl that flares holds a wider object higher up, its centre of mass above the rim). Every
  /// COLL category has instances that fit some basket (the tallest bottles and candle sticks do
  /// not); draw_coll draws among those.
  bool fits(const assets::Asset& obj, const assets::Asset& container) const {
    if (container.receptacles.empty()) return false;
    const auto& r = container.receptacles.front();
    if (obj.center_of_mass.z() > r.inner_depth) return false;
    if (r.inner_radius > 0) return footprint_radius(obj) <= r.inner_radius - settings_.fit_clearance;
    return 2 * std::max(obj.bounding_half_extents.x(), obj.bounding_half_extents.y()) <= 2 * r.inner_half_extents.minCoeff() - settings_.fit_clearance;
  }

  bool draw_coll(SceneSpec& s, Draw& d) {
    // the category uniformly; within it an instance that fits some container (all instances when
    // none does)
    const auto instances = library_.category(d.pick(coll_categories()));
    std::vector<const assets::Asset*> containers;
    for (const auto& c : coll_containers())
      for (const auto* a : library_.category(c)) containers.push_back(a);
    std::vector<const assets::Asset*> fitting;
    for (const auto* o : instances)
      for (const auto* c : containers)
        if (fits(*o, *c)) {
          fitting.push_back(o);
          break;
        }
    const assets::Asset& obj = *d.pick(fitting.empty() ? instances : fitting);
    std::vector<const assets::Asset*> hosts;
    for (const auto* c : containers)
      if (fits(obj, *c)) hosts.push_back(c);
    if (hosts.empty()) {  // the widest opening
      const assets::Asset* widest = containers.front();
      for (const auto* c : containers)
        if (c->bounding_half_extents.x() > widest->bounding_half_extents.x()) widest = c;
      hosts.push_back(widest);
    }
    const assets::Asset& box = *d.pick(hosts);
    const double place_h = asset_height(box) + grasp_height(obj) + settings_.validation.place_clearance;
    const int c = place_object(s, d, box, place_h, false);
    if (c < 0) return false;
    const int o = place_object(s, d, obj, grasp_height(obj), true);
    if (o < 0) return false;
    s.goal.object = o;
    s.goal.container = c;
    return true;
  }

  bool draw_aln(SceneSpec& s, Draw& d) {
    const assets::Asset& obj = pick_instance(d, d.pick(aln_categories()));
    const double h = grasp_height(obj);
    const int o = place_object(s, d, obj, h, true);
    if (o < 0) return false;
    const double r = keepout(obj, true);
    for (int t = 0; t < settings_.placement_tries; ++t) {
      const auto p = reachable_spot(s, d, h, r);
      if (!p) return false;
      if ((*p - s.objects[static_cast<std::size_t>(o)].pose.translation.head<2>()).norm() < settings_.min_goal_distance) continue;
      s.goal.object = o;
      s.goal.goal_pose = upright(obj, *p, s.table.top_center.z(), d.uniform(-0.5 * 3.14159265358979323846, 0.5 * 3.14159265358979323846));
      s.goal.symmetry = asset_symmetry(obj);
      discs_.push_back({*p, r});  // keeps obstacles off the goal
      return true;
    }
    return false;
  }

  /// OVR: the object, then a goal spot far enough that the obstacle fits halfway between them
  /// (gap to each footprint), then the obstacle there. The obstacle keeps home_keepout from the
  /// line from home_xy to the object (the open gripper's way to it: what the arm carries over
  /// is the obstacle between the object and its goal).
  bool draw_ovr(SceneSpec& s, Draw& d) {
    const assets::Asset& obj = pick_instance(d, d.pick(ovr_categories()));
    std::vector<const assets::Asset*> tall;
    for (const auto* a : library_.category(d.pick(ovr_obstacle_categories())))
      if (asset_height(*a) >= settings_.ovr_min_obstacle_height && asset_height(*a) <= settings_.ovr_max_obstacle_height) tall.push_back(a);
    if (tall.empty()) return false;
    const assets::Asset& wall = *d.pick(tall);
    const double h = grasp_height(obj);
    const int o = place_object(s, d, obj, h, true);
    if (o < 0) return false;
    const double r = keepout(obj, true), rw = footprint_radius(wall);
    const math::Pose<double>& start = s.objects[static_cast<std::size_t>(o)].pose;
    const Eigen::Vector2d from = start.translation.head<2>();
    for (int t = 0; t < settings_.placement_tries; ++t) {
      const auto p = reachable_spot(s, d, h, r);
      if (!p) return false;
      const Eigen::Vector2d mid = 0.5 * (from + *p), way = from - settings_.home_xy;
      const double along = way.squaredNorm() > 1e-12 ? std::clamp((mid - settings_.home_xy).dot(way) / way.squaredNorm(), 0.0, 1.0) : 0.0;
      const double dist = (*p - from).norm();
      if (dist < 2 * (r + rw + settings_.gap) || dist > settings_.ovr_max_goal_distance || !on_table(s, mid, rw) || !free(mid, rw) ||
          (settings_.home_xy + along * way - mid).norm() < rw + settings_.home_keepout)
        continue;
      s.goal.object = o;
      s.goal.goal_pose = start;
      s.goal.goal_pose.translation.head<2>() = *p;
      s.goal.symmetry = asset_symmetry(obj);
      discs_.push_back({*p, r});  // keeps obstacles off the goal
      PlacedAsset w;
      w.asset_id = wall.id;
      w.pose = upright(wall, mid, s.table.top_center.z(), s.setting == Setting::randomized ? d.uniform(-3.14159265358979323846, 3.14159265358979323846) : 0.0);
      if (s.setting == Setting::randomized && d.chance(0.5)) recolor(w.appearance, d);
      s.obstacles.push_back(w);
      s.goal.obstacle = static_cast<int>(s.obstacles.size()) - 1;
      discs_.push_back({mid, rw});
      return true;
    }
    return false;
  }

  bool draw_stk(SceneSpec& s, Draw& d) {
    const auto inst = library_.category(d.pick(stk_categories()));
    // distinct widths, largest first
    std::vector<const assets::Asset*> by_width;
    for (const auto* a : inst) {
      bool dup = false;
      for (const auto* b : by_width) dup = dup || std::abs(b->bounding_half_extents.x() - a->bounding_half_extents.x()) < 1e-3;
      if (!dup) by_width.push_back(a);
    }
    const int n = std::min(d.integer(2, 4), static_cast<int>(by_width.size()));
    // choose n of them (keep order by width after the choice)
    std::vector<const assets::Asset*> chosen = by_width;
    while (static_cast<int>(chosen.size()) > n) chosen.erase(chosen.begin() + d.integer(0, static_cast<int>(chosen.size()) - 1));
    std::sort(chosen.begin(), chosen.end(), [](const assets::Asset* a, const assets::Asset* b) {
      return a->bounding_half_extents.x() > b->bounding_half_extents.x();
    });
    double stack = 0;
    for (std::size_t k = 0; k < chosen.size(); ++k) {
      const auto* a = chosen[k];
      // the bottom item's band is where the whole stack is placed: reachable at its top
      const double h = k == 0 ? 0.0 : grasp_height(*a);
      if (k == 0) {
        for (std::size_t j = 0; j < chosen.size(); ++j) stack += asset_height(*chosen[j]);
      }
      const Eigen::Vector2d bottom = k == 0 ? Eigen::Vector2d::Zero() : Eigen::Vector2d(s.objects[static_cast<std::size_t>(s.goal.items.front())].pose.translation.head<2>());
      const int i = place_object(s, d, *a, k == 0 ? stack - asset_height(*chosen.back()) + grasp_height(*chosen.back()) + settings_.validation.place_clearance : h, true,
                                 k == 0 ? nullptr : &bottom, settings_.stk_spread);
      if (i < 0) return false;
      s.goal.items.push_back(i);
    }
    return true;
  }

  bool draw_arr(SceneSpec& s, Draw& d) {
    using K = Relation::Kind;
    static const std::array<K, 7> kinds{K::left_of, K::right_of, K::in_front_of, K::behind, K::next_to, K::between, K::in_a_row};
    Relation rel;
    rel.kind = d.pick(kinds);  // each kind equally often
    const int n = (rel.kind == K::between || rel.kind == K::in_a_row) ? 3 : d.integer(2, 3);
    std::vector<int> idx;
    for (int k = 0; k < n; ++k) {
      const assets::Asset& a = pick_instance(d, d.pick(arr_categories()));
      const int i = place_object(s, d, a, grasp_height(a), true);
      if (i < 0) return false;
      idx.push_back(i);
    }
    rel.objects = {idx[0]};
    if (rel.kind == K::between || rel.kind == K::in_a_row) rel.references = {idx[1], idx[2]};
    else rel.references = {idx[static_cast<std::size_t>(d.integer(1, n - 1))]};
    const auto& a = library_.get(s.objects[static_cast<std::size_t>(idx[0])].asset_id, "ARR object");
    const double r = keepout(a, true), h = grasp_height(a);
    auto pos = [&](int i) { return Eigen::Vector2d(s.objects[static_cast<std::size_t>(i)].pose.translation.head<2>()); };
    auto ref_r = [&](int i) { return discs_[static_cast<std::size_t>(i)].r; };
    std::vector<Eigen::Vector2d> candidates;
    const Eigen::Vector2d b = pos(rel.references[0]);
    const double dist = std::max(settings_.relation_distance, r + ref_r(rel.references[0]) + settings_.gap);
    switch (rel.kind) {
      case K::left_of: candidates = {b + Eigen::Vector2d(0, -dist)}; break;
      case K::right_of: candidates = {b + Eigen::Vector2d(0, dist)}; break;
      case K::in_front_of: candidates = {b + Eigen::Vector2d(dist, 0)}; break;
      case K::behind: candidates = {b + Eigen::Vector2d(-dist, 0)}; break;
      case K::next_to: candidates = {b + Eigen::Vector2d(0, dist), b + Eigen::Vector2d(0, -dist), b + Eigen::Vector2d(dist, 0), b + Eigen::Vector2d(-dist, 0)}; break;
      case K::between: candidates = {0.5 * (b + pos(rel.references[1]))}; break;
      case K::in_a_row: {
        const Eigen::Vector2d c = pos(rel.references[1]);
        const Eigen::Vector2d u = (c - b).normalized();
        const double step = std::max((c - b).norm(), dist);
        candidates = {c + step * u, b - step * u, 0.5 * (b + c)};
        break;
      }
    }
    // the relation judged on centres of mass (as the success predicate): it must not hold at the
    // start (with wider margins) and must hold at the spot (with tighter ones)
    const auto& pose0 = s.objects[static_cast<std::size_t>(idx[0])].pose;
    const Eigen::Vector2d com_offset = (pose0.rotation * a.center_of_mass).head<2>();
    const std::size_t m = 1 + rel.references.size();  // subject, then references
    std::array<Eigen::Vector2d, 3> centres;
    for (std::size_t k = 0; k < m; ++k) {
      const int i = k == 0 ? idx[0] : rel.references[k - 1];
      const auto& o = s.objects[static_cast<std::size_t>(i)];
      centres[k] = (o.pose.translation + o.pose.rotation * library_.get(o.asset_id, "ARR object").center_of_mass).head<2>();
    }
    const std::span<const Eigen::Vector2d> cs(centres.data(), m);
    if (geometry::relation_holds(rel.kind, cs, settings_.relations.tightened(-settings_.relation_margin))) return false;
    const Eigen::Vector2d start = pos(idx[0]);
    for (const auto& p : candidates) {
      if (!settings_.band.contains(p, h) || !on_table(s, p, r) || !free(p, r, idx[0])) continue;
      if ((p - start).norm() < settings_.min_goal_distance) continue;
      centres[0] = p + com_offset;
      if (!geometry::relation_holds(rel.kind, cs, settings_.relations.tightened(settings_.relation_margin))) continue;
      rel.spots = {Eigen::Vector3d(p.x(), p.y(), s.objects[static_cast<std::size_t>(idx[0])].pose.translation.z())};
      discs_.push_back({p, r});
      s.goal.relations = {rel};
      return true;
    }
    return false;
  }

  SamplerSettings settings_;
  AssetLibrary library_;
  SceneValidator validator_;
  language::Library language_;
  std::vector<Disc> discs_;
};

}  // namespace manisoft::scene
