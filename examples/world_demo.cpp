// world_demo: the ManiSoft tabletop world: table, the soft arm mounted behind the table
// (tabletop_scene.hpp), the parallel gripper and eight objects. It
//   1. (--map) maps the reachable workspace over the table top for 9 candidate mounts (random
//      bounded actuations settled to equilibrium) and prints the coverage table plus an ASCII map
//      of the chosen mount (and writes it as a PGM image; --mount H,PITCH maps that one only),
//   2. puts the target cube at (0.5, 0) on the table and solves the inverse statics
//      (rod::InverseStatics, within the actuation limits) for the tool-down gripper poses above
//      the cube, around it, at a drop-off point 15 cm to the side and down,
//   3. runs the scripted sequence (the equilibria's feed-forward torques ramped open loop, S = 1
//      at the cube, S = 0 at the drop-off) in ArmWorld and writes the trace, one row per control
//      step (7 substeps of 2e-4 s, 714 Hz).
//
// Usage: world_demo [--out world_trace.csv] [--map] [--map-pgm workspace.pgm] [--samples N] [--mount H,PITCH]
//
// Trace schema (CSV, comma separated, one header row, then one row per control step; SI units,
// lab frame, z up; quaternions w, x, y, z; the row is written after the control step's substeps):
//   step                  control step index (0 = initial state, before any substep)
//   time                  simulated time [s]
//   S                     gripper command state (0 open, 1 closed)
//   finger_width          visible distance between the fingers [m]: 0.10 open, the held object's
//                         width along the closing axis when holding, 0 when closed on nothing
//   held                  index of the held object in the object list below, -1 if none
//   gripper_px..pz        gripper frame origin (centre of the palm's top face, where the rod
//                         tip attaches) [m]
//   gripper_qw..qz        gripper orientation (its z axis = approach direction, x = closing axis)
//   node{i}_x..z          rod centreline, nodes i = 0 (base) .. 20 (tip) [m]
//   {name}_px..pz         each object's shape-frame origin [m] (object list: cube, block,
//   {name}_qw..qz         carton, can, bottle, ball, marker, bowl, in this column order)
// Events (grasp, release, slip, objects leaving the table) are printed at the end.
#include <Eigen/Core>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "manisoft/control/tool_down.hpp"
#include "manisoft/rod/inverse_statics.hpp"
#include "manisoft/rod/settle.hpp"
#include "manisoft/world/arm_world.hpp"
#include "manisoft/world/tabletop_scene.hpp"
#include "cli_checks.hpp"
#include "output_file.hpp"

namespace {

using namespace manisoft;
using namespace manisoft::geometry;
using namespace manisoft::rigid;
using Vec3 = Eigen::Vector3d;
using Array3 = Eigen::Matrix<double, Eigen::Dynamic, 3>;
constexpr double kDt = 2e-4;

using Arm = rod::CosseratRod<double, rod::damping::AnalyticalLinear, rod::bc::ClampedBase, rod::integrator::PositionVerlet, rod::forcing::Gravity,
                        rod::forcing::ElementTorques>;

/// Arm equilibria under given element torques (rod only; the gripper as a tip load of its weight).
class EquilibriumSampler {
 public:
  explicit EquilibriumSampler(const rod::RodParameters<double>& rp, double gripper_mass, double grasp_offset)
      : rod_(rp, kDt, rod::damping::UniformExp<double>(20.0)), start_(rod_.state()), grasp_offset_(grasp_offset) {
    rod_.forcing<rod::forcing::TipLoad>().force_lab = Vec3(0, 0, -9.81 * gripper_mass);
  }
  struct Result {
    bool settled = false;
    Vec3 grasp_center = Vec3::Zero();
    Vec3 tool_axis = Vec3::Zero();  ///< d3 of the last element
    double min_node_z = 0;
  };
  /// Settles from the straight rod under `torques` (at most 3 s).
  Result settle(const Array3& torques) {
    rod_.restore(start_, 0);
    rod_.forcing<rod::forcing::ElementTorques>().set(torques);
    rod::SettleCriteria<double> rest;
    rest.min_time = 0.3;
    rest.max_time = 3.0;
    rest.speed = 2e-4;
    Result r;
    r.settled = rod::settle(rod_, rest);
    const auto tip = rod_.state().tip_pose();
    r.tool_axis = tip.rotation.col(2);
    r.grasp_center = tip.translation + grasp_offset_ * r.tool_axis;
    r.min_node_z = rod_.state().positions.col(2).minCoeff();
    return r;
  }
  int n_elements() const { return rod_.n_elements(); }

 private:
  rod::SettlingRod<double> rod_;
  rod::RodState<double> start_;
  double grasp_offset_;
};

/// Uniform in [-1, 1) from the engine's raw output (portable across standard libraries).
double symmetric_uniform(std::mt19937_64& rng) { return 2.0 * double(rng() >> 11) * 0x1.0p-53 - 1.0; }

/// The tool-down gripper pose whose grasp centre is at `grasp_center` (closing axis along x).
math::Pose<double> tool_down(const Vec3& grasp_center, const interaction::ParallelGripperParameters& gp) {
  return control::tool_down_pose(grasp_center, 0.0, gp.grasp_center());
}

// ---- 1. actuations sampled by the map -----------------------------------------------------------------

/// The actuation family the map samples: per bend axis c in {0, 1} a uniform couple a_c on
/// elements 1..n-1 plus a tip couple t_c; parameters (a_0, t_0, a_1, t_1).
Array3 family(const Eigen::Vector4d& p, int n) {
  Array3 t = Array3::Zero(n, 3);
  for (int k = 1; k < n; ++k) {
    t(k, 0) = p[0];
    t(k, 1) = p[2];
  }
  t(n - 1, 0) += p[1];
  t(n - 1, 1) += p[3];
  return t;
}

// ---- 2. workspace map -----------------------------------------------------------------------

struct MapResult {
  int grid_x = 8, grid_y = 10;  ///< 10 cm cells over the 0.8 x 1.0 m top
  std::vector<int> hits;        ///< grasp-capable equilibria per cell
  int samples = 0, settled = 0, clear = 0;
  int covered() const {
    int c = 0;
    for (int h : hits) c += h > 0;
    return c;
  }
};


/// Random actuations of the script's family within the reach task's actuation limits (|tau| <=
/// 150 N m bend per element; here at most 10 N m distributed and 150 N m at the tip in the
/// vertical plane, 5 and 40 N m sideways), settled with the gripper's weight. A sample is
/// grasp-capable when the arm (nodes, radius 5 cm) clears the top, the grasp centre is 2-20 cm
/// above it and the tool axis within 45 degrees of straight down.
MapResult map_workspace(const world::ArmMount& mount, int samples) {
  const world::TableDesc table = world::tabletop_table();
  const interaction::ParallelGripperParameters gp;
  EquilibriumSampler solver(world::tabletop_arm_parameters(mount), gp.mass, gp.grasp_center().z());
  MapResult m;
  m.hits.assign(std::size_t(m.grid_x * m.grid_y), 0);
  const double top = table.top_center.z();
  std::mt19937_64 rng(2024);
  auto u = [&] { return symmetric_uniform(rng); };
  for (int i = 0; i < samples; ++i) {
    const double a0 = 5 * u(), t0 = 40 * u(), a1 = 10 * u(), t1 = 150 * u();
    const Eigen::Vector4d p(a0, t0, a1, t1);
    const auto r = solver.settle(family(p, solver.n_elements()));
    ++m.samples;
    if (!r.settled) continue;
    ++m.settled;
    if (r.min_node_z < top + 0.05) continue;
    ++m.clear;
    const Vec3 g = r.grasp_center;
    if (g.z() < top + 0.02 || g.z() > top + 0.20 || -r.tool_axis.z() < std::cos(std::numbers::pi / 4)) continue;
    const int ix = static_cast<int>(std::floor((g.x() - (table.top_center.x() - table.half_x)) / 0.1));
    const int iy = static_cast<int>(std::floor((g.y() - (table.top_center.y() - table.half_y)) / 0.1));
    if (ix < 0 || ix >= m.grid_x || iy < 0 || iy >= m.grid_y) continue;
    ++m.hits[std::size_t(ix * m.grid_y + iy)];
  }
  return m;
}

void print_map(const MapResult& m) {
  std::printf("      y: -0.5 ............ +0.5\n");
  for (int ix = m.grid_x - 1; ix >= 0; --ix) {
    std::printf("x %.2f  ", 0.1 * ix + 0.05);
    for (int iy = 0; iy < m.grid_y; ++iy) {
      const int h = m.hits[std::size_t(ix * m.grid_y + iy)];
      std::printf("%c", h == 0 ? '.' : (h < 3 ? 'o' : '#'));
      std::printf(" ");
    }
    std::printf("\n");
  }
  std::printf("(rows: cell centre x [m] from the back edge, arm base at x = -0.05; '.' none, 'o' 1-2, '#' >= 3\n"
              " grasp-capable equilibria per 10 cm cell)\n");
}

void write_pgm(const MapResult& m, const std::string& path) {
  const int scale = 20;
  std::ofstream out(path, std::ios::binary);
  out << "P5\n" << m.grid_y * scale << " " << m.grid_x * scale << "\n255\n";
  int peak = 1;
  for (int h : m.hits) peak = std::max(peak, h);
  for (int row = 0; row < m.grid_x * scale; ++row) {
    const int ix = m.grid_x - 1 - row / scale;  // far edge of the table at the top of the image
    for (int col = 0; col < m.grid_y * scale; ++col) {
      const int h = m.hits[std::size_t(ix * m.grid_y + col / scale)];
      out.put(static_cast<char>(h == 0 ? 0 : 80 + (175 * h) / peak));
    }
  }
}

// ---- 3. the scripted run --------------------------------------------------------------------

struct Phase {
  const char* name;
  int target;       ///< index into the actuation list
  double ramp;      ///< s to ramp from the previous torques
  double hold;      ///< s to hold after the ramp
  int s;            ///< gripper state during the phase
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"world_demo: the tabletop world's scripted pick and place (trace CSV), and with --map its reachable workspace"};
  std::string out_path = "world_trace.csv", pgm_path = "workspace.pgm";
  bool do_map = false;
  int samples = 300;
  std::vector<double> mount;
  app.add_option("--out", out_path, "trace CSV to write (default world_trace.csv)");
  app.add_flag("--map", do_map, "map the reachable workspace of 9 candidate mounts first");
  app.add_option("--map-pgm", pgm_path, "the chosen mount's map as a PGM image (implies --map; default workspace.pgm)");
  app.add_option("--samples", samples, "--map: random actuations per mount")->check(manisoft::cli::between(1, 1e6));
  app.add_option("--mount", mount, "--map: map this one mount only: height above the table top (m) and pitch (deg), as H,PITCH")
      ->delimiter(',')->expected(2)->check(manisoft::cli::between(-10, 360));
  manisoft::cli::readable_errors(app, "world_demo");
  if (const int code = manisoft::cli::parse(app, argc, argv); code >= 0) return code;  // 2 after a bad flag
  do_map = do_map || app.count("--map-pgm") > 0 || !mount.empty();
  try {
    const world::ArmMount chosen;
    if (do_map) {
      std::printf("Reachable workspace over the table top: %d random bounded actuations per mount settled with the\n"
                  "gripper's weight; a 10 cm cell counts when a grasp-capable pose (arm clear of the top, grasp centre\n"
                  "2-20 cm above it, tool axis within 45 deg of straight down) lands in it.\n\n", samples);
      std::printf("height above top [m]  pitch [deg]  settled  arm clear  grasp-capable cells (of 80)\n");
      MapResult chosen_map;
      std::vector<double> heights{0.45, 0.6, 0.75}, pitches{0.0, 30.0, 60.0};
      if (!mount.empty()) {  // one mount only
        heights = {mount[0]};
        pitches = {mount[1]};
      }
      for (double h : heights) {
        for (double pitch_deg : pitches) {
          world::ArmMount m;
          m.base_position.z() = world::tabletop_table().top_center.z() + h;
          m.pitch = pitch_deg * std::numbers::pi / 180;
          const MapResult r = map_workspace(m, samples);
          const bool is_chosen = std::abs(m.base_position.z() - chosen.base_position.z()) < 1e-9 && std::abs(m.pitch - chosen.pitch) < 1e-9;
          std::printf("%20.2f  %11.0f  %7d  %9d  %19d%s\n", h, pitch_deg, r.settled, r.clear, r.covered(), is_chosen ? "   <- chosen" : "");
          std::fflush(stdout);
          if (is_chosen) chosen_map = r;
        }
      }
      std::printf("\nChosen mount: base (%.2f, %.2f, %.2f), pitch %.0f deg down:\n", chosen.base_position.x(),
                  chosen.base_position.y(), chosen.base_position.z(), chosen.pitch * 180 / std::numbers::pi);
      print_map(chosen_map);
      write_pgm(chosen_map, pgm_path);
      std::printf("map image: %s\n\n", pgm_path.c_str());
    }
    // ---- the script's actuations: inverse statics of the chosen mount, within the limits
    const double top = world::tabletop_table().top_center.z();
    const interaction::ParallelGripperParameters gp;
    const rod::RodParameters<double> arm = world::tabletop_arm_parameters(chosen);
    const world::ArmWorldSettings settings;
    rod::InverseStatics<double> statics(rod::make_arm_model(arm, gp.mass), {}, settings.limits);
    const Eigen::Vector2d target_xy(0.5, 0.0);
    const Vec3 grasp_at(target_xy.x(), target_xy.y(), top + 0.045);  // fingertips 1 cm above the top
    const Vec3 above = grasp_at + Vec3(0, 0, 0.12);
    const Vec3 carry = grasp_at + Vec3(0.0, 0.15, 0.14);
    const Vec3 place = grasp_at + Vec3(0.0, 0.15, 0.006);
    std::vector<Array3> actuations{Array3::Zero(arm.n_elements, 3)};
    for (const Vec3& target : {above, grasp_at, carry, place}) {
      const auto r = statics.solve_cold(tool_down(target, gp));
      if (!r.within_limits)
        manisoft::detail::fail("no equilibrium within the actuation limits holds the gripper at (", target.transpose(),
                               "): position error ", r.position_error, " m, torque ratio ", r.max_torque_ratio);
      std::printf("grasp centre (%.3f, %.3f, %.3f): equilibrium error %.1e m, largest torque %.0f%% of its limit\n", target.x(),
                  target.y(), target.z(), r.position_error, 100 * r.max_torque_ratio);
      actuations.push_back(statics.feedforward());
    }
    // actuations: 0 rest, 1 above, 2 grasp, 3 carry, 4 place
    const std::vector<Phase> script{
        {"approach", 1, 1.2, 0.6, 0}, {"descend", 2, 0.8, 0.5, 0}, {"close", 2, 0.0, 0.3, 1}, {"lift", 1, 0.6, 0.2, 1},
        {"carry", 3, 0.8, 0.4, 1},    {"lower", 4, 0.6, 0.5, 1},   {"open", 4, 0.0, 0.3, 0}, {"retreat", 3, 0.6, 0.4, 0}};

    // ---- the world
    world::ArmWorld<Arm> world(Arm(arm, kDt, rod::damping::AnalyticalLinear<double>(0.5)), settings);
    const std::vector<rigid::BodyId> objects = world::populate_tabletop(world, target_xy);
    const auto specs = world::tabletop_objects(top, target_xy);
    manisoft::cli::OutputFile trace_file(out_path);  // renamed into place once complete
    std::ostream& trace = trace_file.stream();
    trace.precision(7);
    trace << "step,time,S,finger_width,held,gripper_px,gripper_py,gripper_pz,gripper_qw,gripper_qx,gripper_qy,gripper_qz";
    const int n = world.rod().n_elements();
    for (int i = 0; i <= n; ++i) trace << ",node" << i << "_x,node" << i << "_y,node" << i << "_z";
    for (const auto& o : specs) {
      const std::string nm = o.desc.name;
      trace << "," << nm << "_px," << nm << "_py," << nm << "_pz," << nm << "_qw," << nm << "_qx," << nm << "_qy," << nm << "_qz";
    }
    trace << "\n";
    long control_step = 0;
    auto write_row = [&](int s) {
      const auto& rigid = world.rigid();
      const rigid::BodyId g = world.gripper_body();
      int held = -1;
      for (std::size_t i = 0; i < objects.size(); ++i) {
        if (world.gripper().held() && *world.gripper().held() == objects[i]) held = static_cast<int>(i);
      }
      const Vec3 gx = rigid.position(g);
      const auto gq = rigid.orientation(g);
      trace << control_step << "," << world.time() << "," << s << "," << world.gripper().finger_width() << "," << held << ","
            << gx.x() << "," << gx.y() << "," << gx.z() << "," << gq.w() << "," << gq.x() << "," << gq.y() << "," << gq.z();
      const auto& st = world.rod().state();
      for (int i = 0; i <= n; ++i) trace << "," << st.positions(i, 0) << "," << st.positions(i, 1) << "," << st.positions(i, 2);
      for (const rigid::BodyId b : objects) {
        const Vec3 x = rigid.position(b);
        const auto q = rigid.orientation(b);
        trace << "," << x.x() << "," << x.y() << "," << x.z() << "," << q.w() << "," << q.x() << "," << q.y() << "," << q.z();
      }
      trace << "\n";
    };
    write_row(0);
    const double control_dt = kDt * settings.substeps_per_control_step;
    Array3 current = actuations[0];
    const Vec3 cube_start = world.rigid().position(objects[0]);
    double max_weld = 0;
    for (const auto& ph : script) {
      const Array3 from = current, to = actuations[std::size_t(ph.target)];
      const int ramp = static_cast<int>(std::lround(ph.ramp / control_dt)), hold = static_cast<int>(std::lround(ph.hold / control_dt));
      for (int i = 0; i < ramp + hold; ++i) {
        const double a = ramp > 0 ? std::min(1.0, double(i + 1) / ramp) : 1.0;
        const double smooth = a * a * (3 - 2 * a);  // smoothstep: no torque jerk
        current = from + smooth * (to - from);
        world.control_step(current, ph.s);
        ++control_step;
        max_weld = std::max(max_weld, world.gripper().grip_force());
        write_row(ph.s);
      }
      const Vec3 g = world.gripper().grasp_point(world.rigid());
      std::printf("after %-8s t = %5.2f s: grasp centre (%.3f, %.3f, %.3f), S = %d, held = %s\n", ph.name, world.time(), g.x(), g.y(),
                  g.z(), ph.s, world.gripper().held() ? world.rigid().model(*world.gripper().held()).name.c_str() : "-");
    }
    trace_file.commit();
    const Vec3 cube_end = world.rigid().position(objects[0]);
    std::printf("\ncube moved from (%.3f, %.3f, %.3f) to (%.3f, %.3f, %.3f); largest weld force %.2f N\n", cube_start.x(),
                cube_start.y(), cube_start.z(), cube_end.x(), cube_end.y(), cube_end.z(), max_weld);
    for (const auto& e : world.events()) {
      std::printf("event: t = %.4f s  %-14s %s\n", e.time, to_string(e.kind), e.name.c_str());
    }
    std::printf("trace: %s (%ld control steps)\n", out_path.c_str(), control_step + 1);
  } catch (const Error& e) {
    std::fprintf(stderr, "world_demo: %s\n", e.what());
    return 1;
  }
  return 0;
}
