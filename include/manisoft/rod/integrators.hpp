// Explicit symplectic integrators for a Cosserat rod (PyElastica's symplectic_steppers.py).
// A rod exposes kinematic(h) (x += h v, Q <- exp(-h [w]x) Q, time += h, then the boundary
// values), dynamic(h) (forces at the current configuration, then v += h a, w += h alpha, then the
// boundary rates) and dampen(). Step orders:
//   PositionVerlet: kinematic(dt/2), dynamic(dt), dampen, kinematic(dt/2).
//   PEFRL (Omelyan, Mryglod & Folk 2002, position-extended Forest-Ruth-like, 4th order):
//     kinematic(xi dt), dynamic((1 - 2 lambda) dt / 2), kinematic(chi dt), dynamic(lambda dt),
//     kinematic((1 - 2 (chi + xi)) dt), dynamic(lambda dt), kinematic(chi dt),
//     dynamic((1 - 2 lambda) dt / 2), dampen, kinematic(xi dt).
// Damping is applied once per step with the full dt, after the last dynamic stage.
// PEFRL's fourth order holds for position-dependent forces; the rod's velocity-dependent torques
// ((J w / e) x w and the dilatation-rate term) enter the kicks explicitly and leave a small
// first-order error (tests/rod/test_rod_analytic.cpp measures it against PositionVerlet's).
#pragma once

namespace manisoft::rod::integrator {

struct PositionVerlet {
  static constexpr int force_evaluations = 1;
  template <typename Rod, typename Scalar>
  static void step(Rod& rod, Scalar dt) {
    rod.kinematic(dt / 2);
    rod.dynamic(dt);
    rod.dampen();
    rod.kinematic(dt / 2);
  }
};

struct PEFRL {
  static constexpr int force_evaluations = 4;
  static constexpr double xi = 0.1786178958448091;
  static constexpr double lambda = -0.2123418310626054;
  static constexpr double chi = -0.06626458266981849;

  template <typename Rod, typename Scalar>
  static void step(Rod& rod, Scalar dt) {
    const Scalar x = Scalar(xi), l = Scalar(lambda), c = Scalar(chi);
    rod.kinematic(x * dt);
    rod.dynamic((Scalar(1) - Scalar(2) * l) * dt / 2);
    rod.kinematic(c * dt);
    rod.dynamic(l * dt);
    rod.kinematic((Scalar(1) - Scalar(2) * (c + x)) * dt);
    rod.dynamic(l * dt);
    rod.kinematic(c * dt);
    rod.dynamic((Scalar(1) - Scalar(2) * l) * dt / 2);
    rod.dampen();
    rod.kinematic(x * dt);
  }
};

}  // namespace manisoft::rod::integrator
