// SPDX-License-Identifier: MIT
// Doors on derived walls: each Connection becomes an opening in a wall the two rooms share,
// clear of the walls that meet it (their footprints within reach of a passing robot) and of
// other doors. Then every room is made reachable: a room no door reaches gets one to a
// reached neighbour.
#pragma once

#include <string>
#include <vector>

#include "walls.hpp"

namespace msgraphs::sim::building {

struct PlacedDoor {
  int wall = -1;
  int a = -1, b = -1;  ///< the rooms it joins
  double offset_m = 0, width_m = 0, height_m = 0;
  Vec2 centre = Vec2::Zero();  ///< on the wall's centre line
  Vec2 into_a = Vec2::Zero();  ///< unit normal of the wall pointing into room a
};

/// Distance kept between a door and any other wall's footprint across the door's wall:
/// a 0.35 m robot radius, a 5 cm margin and half a 0.1 m planning cell.
inline constexpr double kDoorReach_m = 0.45;

class DoorPlacer {
 public:
  DoorPlacer(const Plan& plan, std::vector<PlanWall>& walls);

  /// Places every connection of the plan (followers where their original went, mapped).
  /// Connections that could not be placed are listed in failed(); followers that had to be
  /// placed elsewhere in displaced().
  void PlaceAll();
  /// Adds a door from every room no door reaches to a reached neighbour. False when a room
  /// shares no usable wall with any reached room.
  bool ConnectAll(std::string& error);

  const std::vector<PlacedDoor>& doors() const { return doors_; }
  /// Door of connection c, or nullptr.
  const PlacedDoor* door_of(int connection) const;
  const std::vector<int>& failed() const { return failed_; }
  const std::vector<int>& displaced() const { return displaced_; }

 private:
  bool Place(const Connection& c, int index);
  bool PlaceAt(const Connection& c, int b, const Vec2& centre, int index);
  int ResolveCorridor(int a) const;
  std::vector<std::pair<double, double>> FreeIntervals(int wall, double s0, double s1) const;
  double DoorHeight(const Connection& c) const;
  void Add(int wall, int a, int b, double offset, double width, double height, int index);

  const Plan& plan_;
  std::vector<PlanWall>& walls_;
  std::vector<std::vector<std::pair<double, double>>> blocked_;  // per wall, by other walls
  std::vector<PlacedDoor> doors_;
  std::vector<int> door_of_connection_;
  std::vector<int> failed_, displaced_;
};

}  // namespace msgraphs::sim::building
