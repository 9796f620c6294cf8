// SPDX-License-Identifier: MIT
#include "world_writer.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <numbers>

namespace msgraphs::sim {
namespace {

// Shortest decimal that parses back to exactly `v` (std::to_chars' guarantee).
std::string Number(double v) {
  if (v == 0.0) v = 0.0;  // no "-0"
  char buffer[40];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), v);
  return std::string(buffer, result.ptr);
}

// Degrees: the parser multiplies by pi/180, so radians cannot round-trip exactly in general;
// 1e-9 degrees is far below anything a world describes, and whole or 1e-4 degree values
// (what people and the building generator write) come back exactly.
std::string Degrees(double rad) {
  const double deg = std::round(rad * (180.0 / std::numbers::pi) * 1e9) / 1e9;
  return Number(deg);
}

std::string Token(const std::string& s, const char* fallback) {
  if (s.empty()) return fallback;
  std::string out = s;
  for (char& c : out) {
    if (c == '#' || c == '=' || static_cast<unsigned char>(c) <= ' ') c = '_';
  }
  return out;
}

std::string Options(int level, const char* material, const char* default_material) {
  std::string out;
  if (level != 0) out += " level=" + std::to_string(level);
  if (std::string(material) != default_material) out += std::string(" material=") + material;
  return out;
}

}  // namespace

std::string WriteWorld(const World& world) {
  std::string out = "msgraphs-world " + std::to_string(kWorldFormatVersion) + "\n";
  // The parser joins the name's words with single spaces; write it that way.
  std::string name;
  for (char c : world.name) {
    const bool space = c == '#' || static_cast<unsigned char>(c) <= ' ';
    if (space) {
      if (!name.empty() && name.back() != ' ') name += ' ';
    } else {
      name += c == '=' ? '_' : c;
    }
  }
  while (!name.empty() && name.back() == ' ') name.pop_back();
  if (!name.empty()) out += "name " + name + "\n";
  for (const Level& l : world.levels) {
    out += "level " + std::to_string(l.index) + " " + Number(l.floor_z_m) + " " +
           (l.ceiling_height_m ? Number(*l.ceiling_height_m) : std::string("none")) + "\n";
  }
  for (const Wall& w : world.walls) {
    out += "wall " + Token(w.id, "wall") + " " + Number(w.start.x()) + " " + Number(w.start.y()) +
           " " + Number(w.end.x()) + " " + Number(w.end.y()) + " " + Number(w.thickness_m) + " " +
           Number(w.height_m) + Options(w.level, ToString(w.material), "painted") + "\n";
    for (const Door& d : w.doors) {
      out += "door " + Token(w.id, "wall") + " " + Number(d.offset_m) + " " + Number(d.width_m) +
             " " + Number(d.height_m) + "\n";
    }
  }
  for (const Room& r : world.rooms) {
    out += "room " + Token(r.id, "room") + " " + Token(r.name, "room");
    for (const auto& p : r.polygon) out += " " + Number(p.x()) + " " + Number(p.y());
    out += Options(r.level, "painted", "painted") + "\n";
  }
  for (const Box& b : world.boxes) {
    out += "box " + Number(b.centre.x()) + " " + Number(b.centre.y()) + " " + Degrees(b.yaw_rad) +
           " " + Number(b.size_m.x()) + " " + Number(b.size_m.y()) + " " + Number(b.size_m.z()) +
           Options(b.level, ToString(b.material), "wood") + "\n";
  }
  for (const Cylinder& c : world.cylinders) {
    out += "cylinder " + Number(c.centre.x()) + " " + Number(c.centre.y()) + " " +
           Number(c.radius_m) + " " + Number(c.height_m) +
           Options(c.level, ToString(c.material), "concrete") + "\n";
  }
  return out;
}

bool SaveWorld(const World& world, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) return false;
  out << WriteWorld(world);
  return static_cast<bool>(out.flush());
}

}  // namespace msgraphs::sim
