// SPDX-License-Identifier: MIT
// The procedural building generator: a seed gives a building, deterministically (the same
// written bytes on any machine: counter-based random streams, ordered containers, coordinates
// rounded to 0.1 mm). Every building passes ParseWorld's validation, has at most 40 rooms, fits
// 120 x 120 m in its own frame, and every room is reachable through doors by a 0.35 m radius
// robot. docs/simulator.md, "Generated buildings".
#pragma once

#include <cstdint>

#include "features.hpp"
#include "options.hpp"
#include "world.hpp"

namespace msgraphs::sim::building {

inline constexpr int kMaxRooms = 40;
inline constexpr double kMaxFootprint_m = 120.0;

/// The building of `seed` with `options` (CheckOptions must accept them; values it would
/// refuse are replaced by drawn ones). Fills `features` when given. Allocates.
World GenerateBuilding(std::uint64_t seed,
                       const BuildingOptions& options,
                       BuildingFeatures* features = nullptr);

}  // namespace msgraphs::sim::building
