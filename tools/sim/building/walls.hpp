// SPDX-License-Identifier: MIT
// Walls derived from room outlines: every stretch of a room's outline becomes wall. Where two
// rooms share it the wall is interior, where one room meets the outside it is exterior.
// Collinear stretches of one kind are one wall (a corridor's side wall runs past every room
// it serves), on the rooms' outlines as centre lines, like the shipped worlds.
#pragma once

#include <string>
#include <vector>

#include "plan.hpp"

namespace msgraphs::sim::building {

/// A stretch of a wall between one pair of rooms (-1: outside), `left` on the wall's
/// normal() side; s0 < s1 measured from the wall's start.
struct WallSpan {
  double s0_m = 0, s1_m = 0;
  int left = -1, right = -1;
};

struct PlanWall {
  Wall wall;  ///< id, centre line, thickness, height, material; doors added later
  bool exterior = false;
  std::vector<WallSpan> spans;
};

/// Walls for every room outline of `plan` (thicknesses, materials from plan.walls, height
/// plan.ceiling_m). False with `error` when two rooms overlap along an outline.
bool BuildWalls(const Plan& plan, std::vector<PlanWall>& walls, std::string& error);

}  // namespace msgraphs::sim::building
