// How two surfaces' material coefficients combine into one contact's: friction as the geometric
// mean sqrt(mu_a mu_b) (a slippery surface stays slippery against anything; Box2D and MuJoCo's
// default use the same family of rules), restitution as the larger of the two. Every contact law
// of the library (rigid pairs, rod elements against bodies) uses these two functions.
#pragma once

#include <algorithm>
#include <cmath>

namespace manisoft::contact {

inline double mix_friction(double mu_a, double mu_b) { return std::sqrt(mu_a * mu_b); }
inline double mix_restitution(double e_a, double e_b) { return std::max(e_a, e_b); }

}  // namespace manisoft::contact
