// SPDX-License-Identifier: MIT
// Resolving BuildingOptions into Choices: forced values are kept, the rest drawn from the
// seed, each from its own random stream (so forcing one choice does not change the others).
#pragma once

#include <cstdint>

#include "options.hpp"
#include "styles.hpp"

namespace msgraphs::sim::building {

Choices Resolve(std::uint64_t seed, const BuildingOptions& options);

}  // namespace msgraphs::sim::building
