// rod_demo: the ManiSoft soft arm (1 m Cosserat rod, clamped at the origin pointing along +x,
// gravity, PyElastica's analytical damping) driven by Elastica-RL style B-spline muscle torques
// (an internal couple: element k gets T_k - T_{k+1}, see forcing.hpp).
// Prints a side view (x-z plane) of the centreline at a few instants and the tip trajectory.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "manisoft/rod.hpp"

namespace {

using Rod = manisoft::rod::CosseratRod<double, manisoft::rod::damping::AnalyticalLinear, manisoft::rod::bc::ClampedBase,
                                  manisoft::rod::integrator::PositionVerlet, manisoft::rod::forcing::Gravity,
                                  manisoft::rod::forcing::ElasticaRLMuscleTorques>;

/// Draws the centrelines (x right, z up) into a character grid, one symbol per snapshot.
void draw(const std::vector<std::pair<char, Eigen::MatrixX3d>>& shapes) {
  const int width = 72, height = 28;
  const double x_min = -0.2, x_max = 1.1, z_min = -0.7, z_max = 0.7;
  std::vector<std::string> grid(height, std::string(width, ' '));
  auto plot = [&](double x, double z, char c) {
    const int col = static_cast<int>(std::lround((x - x_min) / (x_max - x_min) * (width - 1)));
    const int row = static_cast<int>(std::lround((z_max - z) / (z_max - z_min) * (height - 1)));
    if (col >= 0 && col < width && row >= 0 && row < height) grid[row][col] = c;
  };
  for (double x = x_min; x <= x_max; x += 0.01) plot(x, 0, '.');
  for (const auto& [symbol, nodes] : shapes)
    for (int k = 0; k + 1 < nodes.rows(); ++k)
      for (int i = 0; i < 8; ++i) {
        const double a = i / 8.0;
        plot((1 - a) * nodes(k, 0) + a * nodes(k + 1, 0), (1 - a) * nodes(k, 2) + a * nodes(k + 1, 2), symbol);
      }
  plot(0, 0, '#');
  std::printf("side view, x from %.1f to %.1f m (right), z from %.1f to %.1f m (up); '#' is the clamped base\n", x_min, x_max,
              z_min, z_max);
  for (const auto& line : grid) std::printf("|%s|\n", line.c_str());
}

}  // namespace

int main() {
  Rod rod(manisoft::rod::RodParameters<double>{}, 2e-4, manisoft::rod::damping::AnalyticalLinear<double>(0.1));
  auto& muscles = rod.forcing<manisoft::rod::forcing::ElasticaRLMuscleTorques>();
  // Two activation phases (6 control points x {normal, binormal, twist}, scale 75 N m). The
  // muscle is an internal couple: the cross-section near arc length s carries about 75 c(s) N m,
  // against the bending stiffness EI = 49 N m^2 and a gravity moment of up to 38 N m at the base.
  // A positive binormal couple curls the arm upwards: c ~ 1 near the base lifts it against gravity.
  // Then a negative activation, about half as strong (gravity helps), bends it downwards.
  // Feed-forward torques alone leave the arm swinging (the executors in control/ add feedback).
  Eigen::Matrix<double, 6, 3> curl = Eigen::Matrix<double, 6, 3>::Zero(), bend_down = curl;
  curl.col(1) << 1.0, 1.0, 0.9, 0.8, 0.7, 0.5;
  bend_down.col(1) << -0.2, -0.35, -0.5, -0.5, -0.4, -0.25;
  std::vector<std::pair<char, Eigen::MatrixX3d>> shapes{{'0', rod.state().positions}};
  std::printf("   t [s]    tip x     tip y     tip z   [m]   phase\n");
  const double control_dt = 7 * rod.dt();  // 714 Hz control, as in the paper
  for (int control_step = 0; control_step <= 2100; ++control_step) {
    const bool first = control_step < 1050;
    if (control_step == 0 || control_step == 1050) muscles.set_control_points(first ? curl : bend_down);
    if (control_step % 150 == 0) {
      const auto tip = rod.tip_position();
      std::printf("%8.3f %9.4f %9.4f %9.4f   %s\n", control_step * control_dt, tip.x(), tip.y(), tip.z(), first ? "curl up" : "bend down");
    }
    if (control_step == 1049) shapes.emplace_back('1', rod.state().positions);
    if (control_step == 2100) shapes.emplace_back('2', rod.state().positions);
    rod.step(7);
  }
  draw(shapes);
  std::printf("0: initial straight arm, 1: after %.1f s of 'curl up', 2: after %.1f s more of 'bend down'\n", 1050 * control_dt,
              1050 * control_dt);
  return 0;
}
