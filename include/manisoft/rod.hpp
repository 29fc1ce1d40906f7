// Umbrella header for the Cosserat rod: model, state, policies and the composed CosseratRod.
#pragma once

#include "manisoft/rod/cosserat_rod.hpp"
