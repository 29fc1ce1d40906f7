// How two surfaces' material coefficients combine into one contact's: friction as the geometric
// mean sqrt(mu_a mu_b) (a slippery surface stays slippery against anything; Box2D and MuJoCo's
// default use the same family of rules), restitution as the larger of the two, rolling resistance
// as the larger of the two (it comes from the deformation of the softer surface; MuJoCo's default
// mixes its rolling friction by the maximum too). Every contact law of the library (rigid pairs,
// rod elements against bodies) uses these functions.
#pragma once

#include <algorithm>
#include <cmath>

namespace manisoft::contact {

inline double mix_friction(double mu_a, double mu_b) { return std::sqrt(mu_a * mu_b); }
inline double mix_restitution(double e_a, double e_b) { return std::max(e_a, e_b); }
inline double mix_rolling_resistance(double r_a, double r_b) { return std::max(r_a, r_b); }

}  // namespace manisoft::contact
