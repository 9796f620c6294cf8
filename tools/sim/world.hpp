// SPDX-License-Identifier: MIT
// The simulator's world: one or more building levels with walls (2-D segments with thickness
// and height), door openings, rooms (true footprints), and clutter (boxes, cylinders). Format
// and rules: docs/simulator.md. Parsing validates everything and reports "file:line: reason".
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace msgraphs::sim {

inline constexpr int kWorldFormatVersion = 1;

enum class Material : std::uint8_t { kPainted, kConcrete, kWood, kMetal, kFabric, kGlass };
const char* ToString(Material m);
/// Calibrated reflectivity (0..255) the VLP-16 reports for a surface seen head-on.
double Reflectivity(Material m);

struct Level {
  int index = 0;
  double floor_z_m = 0.0;
  std::optional<double> ceiling_height_m;  ///< none: open to the sky
};

struct Door {
  double offset_m = 0.0;  ///< from the wall's start point to the opening's near edge
  double width_m = 0.9;
  double height_m = 2.1;
};

struct Wall {
  std::string id;
  Eigen::Vector2d start, end;
  double thickness_m = 0.15;
  double height_m = 3.0;
  int level = 0;
  Material material = Material::kPainted;
  std::vector<Door> doors;

  double length() const { return (end - start).norm(); }
  Eigen::Vector2d direction() const { return (end - start).normalized(); }
  Eigen::Vector2d normal() const { const Eigen::Vector2d d = direction(); return {-d.y(), d.x()}; }
};

struct Room {
  std::string id;
  std::string name;
  int level = 0;
  std::vector<Eigen::Vector2d> polygon;  ///< counter-clockwise after parsing

  Eigen::Vector2d Centroid() const;
  double Area() const;
  bool Contains(const Eigen::Vector2d& p) const;
};

struct Box {
  Eigen::Vector2d centre;
  double yaw_rad = 0.0;
  Eigen::Vector3d size_m{1, 1, 1};  ///< x, y along the box's axes, z = height from the floor
  int level = 0;
  Material material = Material::kWood;
};

struct Cylinder {
  Eigen::Vector2d centre;
  double radius_m = 0.2;
  double height_m = 3.0;
  int level = 0;
  Material material = Material::kConcrete;
};

struct World {
  std::string name;
  std::vector<Level> levels;
  std::vector<Wall> walls;
  std::vector<Room> rooms;
  std::vector<Box> boxes;
  std::vector<Cylinder> cylinders;

  const Level* FindLevel(int index) const;
  const Room* RoomAt(const Eigen::Vector2d& p, int level) const;
};

struct ParseError {
  int line = 0;  ///< 0: the file as a whole
  std::string reason;
};

/// Parses and validates a world. On failure returns std::nullopt and fills `error`.
std::optional<World> ParseWorld(const std::string& text, ParseError& error);
std::optional<World> LoadWorld(const std::string& path, std::string& error_message);

}  // namespace msgraphs::sim
