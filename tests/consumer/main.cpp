// A downstream project: finds the installed ManiSoft package and steps a rod.
#include <cstdio>

#include <manisoft/rod.hpp>

int main() {
  using Rod = manisoft::CosseratRod<double, manisoft::damping::AnalyticalLinear, manisoft::bc::ClampedBase,
                                    manisoft::integrator::PositionVerlet, manisoft::forcing::Gravity>;
  Rod rod(manisoft::RodParameters<double>{}, 2e-4, manisoft::damping::AnalyticalLinear<double>(0.1));
  rod.step(100);
  const auto tip = rod.tip_position();
  std::printf("tip after 0.02 s: %.6f %.6f %.6f\n", tip.x(), tip.y(), tip.z());
  return tip.z() < 0 && tip.z() > -0.01 ? 0 : 1;  // the arm starts to sag under gravity
}
