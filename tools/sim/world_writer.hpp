// SPDX-License-Identifier: MIT
// The world format v1 writer (docs/simulator.md): ParseWorld(WriteWorld(w)) gives back w.
// Lengths are written in their shortest exact decimal form, so they round-trip bit for bit;
// yaw angles are written in degrees rounded to 1e-9 degrees (the file's unit).
#pragma once

#include <string>

#include "world.hpp"

namespace msgraphs::sim {

/// The text of `world` in format v1. Ids and names that the format cannot hold as one token
/// (empty, whitespace, '#', '=') are written with those characters replaced by '_'. Allocates.
std::string WriteWorld(const World& world);

/// Writes WriteWorld(world) to `path`; false when the file cannot be written.
bool SaveWorld(const World& world, const std::string& path);

}  // namespace msgraphs::sim
