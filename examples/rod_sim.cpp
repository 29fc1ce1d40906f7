// rod_sim: command-line reproduction tool for the Cosserat rod. Runs a clamped rod under gravity,
// torques and damping and writes the tip position and tip directors in the layout of
// PyElastica's reference CSVs (t,tip_x,tip_y,tip_z,d1_x,...,d3_z).
//
//   rod_sim --n 20 --dt 2e-4 --t-end 2 --record-every 0.01 [--gravity]
//           [--damping none|analytical:NU|uniform:GAMMA] [--lab-torque T,UX,UY,UZ]
//           [--follower-couple M1,M2,M3] [--direction X,Y,Z] [--normal X,Y,Z] [--float]
//           [--allow-unstable] --out FILE.csv
//
// --help lists the flags. Bad flags exit 2 with a message naming the flag and the value; a run the
// library refuses (a diverged rod, an unstable time step) or a failed write exits 1 and leaves no
// CSV (the file is written under a temporary name and renamed when complete).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_checks.hpp"
#include "manisoft/rod.hpp"
#include "output_file.hpp"

namespace {

struct Options {
  int n = 20;
  double dt = 2e-4, t_end = 2, record_every = 0.01;
  bool gravity = false, use_float = false, allow_unstable = false;
  std::string damping = "none";
  double damping_value = 0;
  double lab_torque = 0;
  Eigen::Vector3d lab_axis = Eigen::Vector3d::UnitY();
  Eigen::Vector3d follower = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX(), normal = Eigen::Vector3d::UnitZ();
  std::string out;
};

/// Most time steps a run may take (hours of computing at n = 20): a larger --t-end / --dt is a
/// typing mistake, not a simulation.
constexpr double max_steps = 1e8;

[[noreturn]] void usage_error(const std::string& message) {
  std::cerr << "rod_sim: " << message << "\nRun with --help for more information.\n";
  std::exit(2);
}

double parse_number(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v))
    usage_error(flag + " expects a finite number, got '" + text + "'");
  return v;
}

std::vector<double> parse_list(const std::string& flag, const std::string& text, std::size_t count) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) values.push_back(parse_number(flag, item));
  if (values.size() != count) usage_error(flag + " expects " + std::to_string(count) + " comma-separated numbers, got '" + text + "'");
  return values;
}

Eigen::Vector3d vector3(const std::string& flag, const std::string& text) {
  const auto v = parse_list(flag, text, 3);
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

void parse_damping(const std::string& d, Options& o) {
  const auto colon = d.find(':');
  o.damping = d.substr(0, colon);
  if (o.damping == "none") {
    if (colon != std::string::npos) usage_error("--damping none takes no value");
  } else if (o.damping == "analytical" || o.damping == "uniform") {
    if (colon == std::string::npos) usage_error("--damping " + o.damping + " needs a value, e.g. " + o.damping + ":0.1");
    o.damping_value = parse_number("--damping", d.substr(colon + 1));
    if (o.damping_value < 0) usage_error("--damping value must be >= 0 (got " + d.substr(colon + 1) + ")");
  } else {
    usage_error("--damping must be none, analytical:NU or uniform:GAMMA, got '" + d + "'");
  }
}

/// The checks that involve several flags (after CLI11 has checked each flag on its own).
void check_timing(const Options& o) {
  const double ratio = o.record_every / o.dt;
  if (std::abs(ratio - std::round(ratio)) > 1e-6 * ratio || ratio < 0.5)
    usage_error("--record-every must be a whole number of time steps (record-every / dt = " + std::to_string(ratio) + ")");
  if (o.t_end / o.dt > max_steps) {
    char message[256];
    std::snprintf(message, sizeof message, "--t-end %g s is %.3g steps of --dt %g s: at most %.0e steps (--t-end <= %g s at this --dt)", o.t_end,
                  o.t_end / o.dt, o.dt, max_steps, max_steps * o.dt);
    usage_error(message);
  }
}

/// The options; `exit_code` is -1 to go on, else the code to exit with (0 after --help, 2 after
/// a bad flag).
Options parse(int argc, char** argv, int& exit_code) {
  namespace cli = manisoft::cli;
  Options o;
  std::string damping = "none", lab_torque, follower, direction, normal;
  CLI::App app{"rod_sim: a clamped Cosserat rod under gravity, torques and damping; writes the tip position and directors as CSV in "
               "PyElastica's reference layout (t,tip_x,tip_y,tip_z,d1_x,...,d3_z). Exit 0 done, 1 refused by the library, 2 bad flags."};
  app.add_option("--n", o.n, "elements (default 20)")->check(cli::between(2, 1e6));
  app.add_option("--dt", o.dt, "time step, s (default 2e-4)")->check(cli::positive());
  app.add_option("--t-end", o.t_end, "simulated time, s (default 2; at most 1e8 steps)")->check(cli::non_negative());
  app.add_option("--record-every", o.record_every, "CSV row interval, s: a whole number of steps (default 0.01)")->check(cli::positive());
  app.add_flag("--gravity", o.gravity, "gravity along -z");
  app.add_option("--damping", damping, "none (default), analytical:NU or uniform:GAMMA (NU, GAMMA >= 0)");
  app.add_option("--lab-torque", lab_torque, "T,UX,UY,UZ: torque T (N m) about the lab axis U on every element");
  app.add_option("--follower-couple", follower, "M1,M2,M3: couple per unit length in the material frame");
  app.add_option("--direction", direction, "X,Y,Z: the rod's initial direction (default 1,0,0)");
  app.add_option("--normal", normal, "X,Y,Z: the rod's initial normal (default 0,0,1)");
  app.add_flag("--float", o.use_float, "simulate in single precision");
  app.add_flag("--allow-unstable", o.allow_unstable, "run a time step above the stability limit");
  app.add_option("--out", o.out, "CSV file to write")->required();
  cli::readable_errors(app, "rod_sim");
  exit_code = cli::parse(app, argc, argv);
  if (exit_code >= 0) return o;
  parse_damping(damping, o);
  if (!lab_torque.empty()) {
    const auto v = parse_list("--lab-torque", lab_torque, 4);
    o.lab_torque = v[0];
    o.lab_axis = Eigen::Vector3d(v[1], v[2], v[3]);
  }
  if (!follower.empty()) o.follower = vector3("--follower-couple", follower);
  if (!direction.empty()) o.direction = vector3("--direction", direction);
  if (!normal.empty()) o.normal = vector3("--normal", normal);
  check_timing(o);
  return o;
}

template <typename Scalar, template <class> class Damping>
int run(const Options& o, Damping<Scalar> damping) {
  using Rod = manisoft::rod::CosseratRod<Scalar, Damping, manisoft::rod::bc::ClampedBase, manisoft::rod::integrator::PositionVerlet,
                                    manisoft::rod::forcing::Gravity, manisoft::rod::forcing::UniformLabTorque,
                                    manisoft::rod::forcing::ElementTorques>;
  manisoft::rod::RodParameters<Scalar> p;
  p.n_elements = o.n;
  p.direction = o.direction.cast<Scalar>();
  p.normal = o.normal.cast<Scalar>();
  manisoft::rod::forcing::Gravity<Scalar> gravity;
  if (!o.gravity) gravity.acceleration.setZero();
  manisoft::rod::forcing::UniformLabTorque<Scalar> lab;
  lab.torque = Scalar(o.lab_torque);
  lab.direction = o.lab_axis.cast<Scalar>();
  manisoft::rod::forcing::ElementTorques<Scalar> follower;
  const Scalar dt = Scalar(o.dt);
  Rod rod = o.allow_unstable ? Rod(manisoft::rod::allow_unstable_timestep, p, dt, damping, gravity, lab, follower)
                             : Rod(p, dt, damping, gravity, lab, follower);
  // Follower couple m per unit length: m L / n on every element, material frame.
  Eigen::Matrix<Scalar, Eigen::Dynamic, 3> couple(o.n, 3);
  for (int k = 0; k < o.n; ++k) couple.row(k) = (o.follower * (1.0 / o.n)).cast<Scalar>().transpose();
  rod.template forcing<manisoft::rod::forcing::ElementTorques>().set(couple);

  manisoft::cli::OutputFile file(o.out);
  std::ostream& out = file.stream();
  out << "t,tip_x,tip_y,tip_z,d1_x,d1_y,d1_z,d2_x,d2_y,d2_z,d3_x,d3_y,d3_z\n";
  char line[512];
  auto record = [&](long step) {
    const auto& s = rod.state();
    const int last = o.n - 1;
    int len = std::snprintf(line, sizeof line, "%.10g", double(step) * o.dt);
    for (int c = 0; c < 3; ++c) len += std::snprintf(line + len, sizeof line - len, ",%.10g", double(s.positions(o.n, c)));
    for (int c = 0; c < 9; ++c) len += std::snprintf(line + len, sizeof line - len, ",%.10g", double(s.directors(last, c)));
    out << line << '\n';
  };
  const long steps = std::lround(o.t_end / o.dt);
  const long every = std::lround(o.record_every / o.dt);
  record(0);
  const auto start = std::chrono::steady_clock::now();
  for (long i = 1; i <= steps; ++i) {
    rod.step();
    if (i % every == 0) record(i);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  file.commit();  // before the summary: a run whose CSV failed reports no result
  const auto tip = rod.tip_position();
  std::fprintf(stderr, "rod_sim: n=%d %s t=%g s, %ld steps, final tip (%.9f, %.9f, %.9f) m, %.0f steps/s\n", o.n,
               std::is_same_v<Scalar, float> ? "float" : "double", double(steps) * o.dt, steps, double(tip[0]), double(tip[1]),
               double(tip[2]), seconds > 0 ? double(steps) / seconds : 0.0);
  return 0;
}

template <typename Scalar>
int dispatch(const Options& o) {
  if (o.damping == "analytical") return run<Scalar>(o, manisoft::rod::damping::AnalyticalLinear<Scalar>(Scalar(o.damping_value)));
  if (o.damping == "uniform") return run<Scalar>(o, manisoft::rod::damping::UniformExp<Scalar>(Scalar(o.damping_value)));
  return run<Scalar>(o, manisoft::rod::damping::None<Scalar>{});
}

}  // namespace

int main(int argc, char** argv) {
  int exit_code = -1;
  const Options o = parse(argc, argv, exit_code);
  if (exit_code >= 0) return exit_code;
  try {
    return o.use_float ? dispatch<float>(o) : dispatch<double>(o);
  } catch (const manisoft::Error& e) {
    std::cerr << "rod_sim: " << e.what() << "\n";
    return 1;
  }
}
