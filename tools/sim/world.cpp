// SPDX-License-Identifier: MIT
#include "world.hpp"

#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

namespace msgraphs::sim {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

struct Line {
  int number;
  std::vector<std::string> tokens;
  std::map<std::string, std::string> options;  // key=value tokens
};

bool ParseNumber(const std::string& s, double& out) {
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0' && std::isfinite(out);
}

bool ParseInt(const std::string& s, int& out) {
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (end == s.c_str() || *end != '\0' || v < -1000 || v > 1000) return false;
  out = static_cast<int>(v);
  return true;
}

bool ParseMaterial(const std::string& s, Material& m) {
  static const std::map<std::string, Material> kNames = {
      {"painted", Material::kPainted}, {"concrete", Material::kConcrete}, {"wood", Material::kWood},
      {"metal", Material::kMetal},     {"fabric", Material::kFabric},     {"glass", Material::kGlass}};
  const auto it = kNames.find(s);
  if (it == kNames.end()) return false;
  m = it->second;
  return true;
}

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

bool SegmentsCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d) {
  const double d1 = Cross(b - a, c - a), d2 = Cross(b - a, d - a);
  const double d3 = Cross(d - c, a - c), d4 = Cross(d - c, b - c);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

class Parser {
 public:
  explicit Parser(ParseError& error) : error_(error) {}

  bool Fail(int line, std::string reason) {
    error_ = {line, std::move(reason)};
    return false;
  }

  // Reads numbers from tokens[first, first + n).
  bool Numbers(const Line& l, std::size_t first, std::size_t n, std::vector<double>& out) {
    out.clear();
    if (l.tokens.size() < first + n) {
      return Fail(l.number, "'" + l.tokens[0] + "' needs " + std::to_string(n) + " numbers");
    }
    for (std::size_t i = first; i < first + n; ++i) {
      double v = 0;
      if (!ParseNumber(l.tokens[i], v)) return Fail(l.number, "not a finite number: '" + l.tokens[i] + "'");
      out.push_back(v);
    }
    return true;
  }

  bool Options(const Line& l, const std::set<std::string>& allowed, int& level, Material& material) {
    for (const auto& [key, value] : l.options) {
      if (allowed.count(key) == 0) return Fail(l.number, "unknown option '" + key + "' for '" + l.tokens[0] + "'");
      if (key == "level" && !ParseInt(value, level)) return Fail(l.number, "level must be an integer");
      if (key == "material" && !ParseMaterial(value, material)) {
        return Fail(l.number, "unknown material '" + value + "' (painted, concrete, wood, metal, fabric, glass)");
      }
    }
    return true;
  }

  std::optional<World> Run(const std::string& text) {
    std::vector<Line> lines;
    std::istringstream in(text);
    std::string raw;
    int number = 0;
    while (std::getline(in, raw)) {
      ++number;
      if (const auto hash = raw.find('#'); hash != std::string::npos) raw.resize(hash);
      std::istringstream words(raw);
      Line l{number, {}, {}};
      std::string w;
      while (words >> w) {
        const auto eq = w.find('=');
        if (eq != std::string::npos && !l.tokens.empty()) {
          l.options[w.substr(0, eq)] = w.substr(eq + 1);
        } else {
          l.tokens.push_back(w);
        }
      }
      if (!l.tokens.empty()) lines.push_back(std::move(l));
    }
    if (lines.empty()) return Fail(0, "empty world file"), std::nullopt;
    const Line& header = lines.front();
    if (header.tokens[0] != "msgraphs-world" || header.tokens.size() != 2) {
      return Fail(header.number, "first line must be 'msgraphs-world <version>'"), std::nullopt;
    }
    if (header.tokens[1] != std::to_string(kWorldFormatVersion)) {
      return Fail(header.number, "unsupported world format version " + header.tokens[1] + " (this build reads " +
                                     std::to_string(kWorldFormatVersion) + ")"),
             std::nullopt;
    }
    World world;
    std::map<std::string, std::size_t> wall_index;
    std::vector<double> v;
    for (std::size_t i = 1; i < lines.size(); ++i) {
      const Line& l = lines[i];
      const std::string& kind = l.tokens[0];
      int level = 0;
      Material material = Material::kPainted;
      if (kind == "name") {
        for (std::size_t k = 1; k < l.tokens.size(); ++k) world.name += (k > 1 ? " " : "") + l.tokens[k];
      } else if (kind == "level") {
        // level <index> <floor_z> <ceiling_height|none>
        if (l.tokens.size() != 4) return Fail(l.number, "'level' needs <index> <floor_z> <ceiling_height|none>"), std::nullopt;
        Level lv;
        double z = 0;
        if (!ParseInt(l.tokens[1], lv.index) || !ParseNumber(l.tokens[2], z)) {
          return Fail(l.number, "bad level index or floor height"), std::nullopt;
        }
        lv.floor_z_m = z;
        if (l.tokens[3] != "none") {
          double h = 0;
          if (!ParseNumber(l.tokens[3], h) || h < 2.0 || h > 20.0) {
            return Fail(l.number, "ceiling height must be 2..20 m or 'none'"), std::nullopt;
          }
          lv.ceiling_height_m = h;
        }
        if (world.FindLevel(lv.index) != nullptr) return Fail(l.number, "level defined twice"), std::nullopt;
        world.levels.push_back(lv);
      } else if (kind == "wall") {
        // wall <id> <x1> <y1> <x2> <y2> <thickness> <height> [level=] [material=]
        if (l.tokens.size() != 8) return Fail(l.number, "'wall' needs <id> x1 y1 x2 y2 thickness height"), std::nullopt;
        if (!Numbers(l, 2, 6, v) || !Options(l, {"level", "material"}, level, material)) return std::nullopt;
        Wall w{l.tokens[1], {v[0], v[1]}, {v[2], v[3]}, v[4], v[5], level, material, {}};
        if (wall_index.count(w.id) != 0) return Fail(l.number, "wall id '" + w.id + "' used twice"), std::nullopt;
        if (w.length() < 0.05) return Fail(l.number, "wall shorter than 5 cm"), std::nullopt;
        if (w.thickness_m < 0.02 || w.thickness_m > 2.0) return Fail(l.number, "wall thickness must be 0.02..2 m"), std::nullopt;
        if (w.height_m < 0.3 || w.height_m > 20.0) return Fail(l.number, "wall height must be 0.3..20 m"), std::nullopt;
        wall_index[w.id] = world.walls.size();
        world.walls.push_back(std::move(w));
      } else if (kind == "door") {
        // door <wall_id> <offset> <width> <height>
        if (l.tokens.size() != 5) return Fail(l.number, "'door' needs <wall_id> offset width height"), std::nullopt;
        const auto it = wall_index.find(l.tokens[1]);
        if (it == wall_index.end()) return Fail(l.number, "door on unknown wall '" + l.tokens[1] + "' (define the wall first)"), std::nullopt;
        if (!Numbers(l, 2, 3, v)) return std::nullopt;
        Wall& w = world.walls[it->second];
        Door d{v[0], v[1], v[2]};
        if (d.offset_m < 0 || d.width_m < 0.5 || d.offset_m + d.width_m > w.length() + 1e-9) {
          return Fail(l.number, "door must lie inside its wall and be at least 0.5 m wide"), std::nullopt;
        }
        if (d.height_m < 1.0 || d.height_m > w.height_m) return Fail(l.number, "door height must be 1 m .. the wall's height"), std::nullopt;
        for (const Door& o : w.doors) {
          if (d.offset_m < o.offset_m + o.width_m && o.offset_m < d.offset_m + d.width_m) {
            return Fail(l.number, "door overlaps another door in the same wall"), std::nullopt;
          }
        }
        w.doors.push_back(d);
      } else if (kind == "room") {
        // room <id> <name> <x1> <y1> <x2> <y2> <x3> <y3> ... [level=]
        if (!Options(l, {"level"}, level, material)) return std::nullopt;
        const std::size_t n = l.tokens.size() - 3;
        if (l.tokens.size() < 9 || n % 2 != 0) {
          return Fail(l.number, "'room' needs <id> <name> and at least 3 vertices (x y pairs)"), std::nullopt;
        }
        if (!Numbers(l, 3, n, v)) return std::nullopt;
        Room r{l.tokens[1], l.tokens[2], level, {}};
        for (std::size_t k = 0; k < n; k += 2) r.polygon.emplace_back(v[k], v[k + 1]);
        for (const Room& o : world.rooms) {
          if (o.id == r.id) return Fail(l.number, "room id '" + r.id + "' used twice"), std::nullopt;
        }
        const std::size_t m = r.polygon.size();
        for (std::size_t a = 0; a < m; ++a) {
          for (std::size_t b = a + 1; b < m; ++b) {
            if (SegmentsCross(r.polygon[a], r.polygon[(a + 1) % m], r.polygon[b], r.polygon[(b + 1) % m])) {
              return Fail(l.number, "room polygon intersects itself"), std::nullopt;
            }
          }
        }
        double signed_area = 0;
        for (std::size_t a = 0; a < m; ++a) signed_area += Cross(r.polygon[a], r.polygon[(a + 1) % m]);
        if (std::fabs(signed_area) < 2 * 1.0) return Fail(l.number, "room smaller than 1 m^2"), std::nullopt;
        if (signed_area < 0) std::reverse(r.polygon.begin(), r.polygon.end());
        world.rooms.push_back(std::move(r));
      } else if (kind == "box") {
        // box <x> <y> <yaw_deg> <size_x> <size_y> <height> [level=] [material=]
        material = Material::kWood;
        if (l.tokens.size() != 7) return Fail(l.number, "'box' needs x y yaw_deg size_x size_y height"), std::nullopt;
        if (!Numbers(l, 1, 6, v) || !Options(l, {"level", "material"}, level, material)) return std::nullopt;
        if (v[3] < 0.05 || v[4] < 0.05 || v[5] < 0.05 || v[3] > 50 || v[4] > 50 || v[5] > 20) {
          return Fail(l.number, "box sizes must be 0.05..50 m (height ..20 m)"), std::nullopt;
        }
        world.boxes.push_back({{v[0], v[1]}, v[2] * kDegToRad, {v[3], v[4], v[5]}, level, material});
      } else if (kind == "cylinder") {
        // cylinder <x> <y> <radius> <height> [level=] [material=]
        material = Material::kConcrete;
        if (l.tokens.size() != 5) return Fail(l.number, "'cylinder' needs x y radius height"), std::nullopt;
        if (!Numbers(l, 1, 4, v) || !Options(l, {"level", "material"}, level, material)) return std::nullopt;
        if (v[2] < 0.02 || v[2] > 10 || v[3] < 0.05 || v[3] > 20) {
          return Fail(l.number, "cylinder radius must be 0.02..10 m, height 0.05..20 m"), std::nullopt;
        }
        world.cylinders.push_back({{v[0], v[1]}, v[2], v[3], level, material});
      } else {
        return Fail(l.number, "unknown keyword '" + kind + "'"), std::nullopt;
      }
    }
    // Whole-file rules.
    if (world.levels.empty()) return Fail(0, "no 'level' line: every world needs at least one level"), std::nullopt;
    if (world.walls.empty()) return Fail(0, "no walls"), std::nullopt;
    if (world.rooms.empty()) return Fail(0, "no rooms"), std::nullopt;
    auto check_level = [&](int level_index, const std::string& what) {
      if (world.FindLevel(level_index) == nullptr) {
        Fail(0, what + " on undefined level " + std::to_string(level_index));
        return false;
      }
      return true;
    };
    for (const Wall& w : world.walls) {
      if (!check_level(w.level, "wall '" + w.id + "'")) return std::nullopt;
    }
    for (const Room& r : world.rooms) {
      if (!check_level(r.level, "room '" + r.id + "'")) return std::nullopt;
    }
    for (const Box& b : world.boxes) {
      if (!check_level(b.level, "a box")) return std::nullopt;
      if (world.RoomAt(b.centre, b.level) == nullptr) {
        return Fail(0, "a box at (" + std::to_string(b.centre.x()) + ", " + std::to_string(b.centre.y()) +
                           ") is in no room"),
               std::nullopt;
      }
    }
    for (const Cylinder& c : world.cylinders) {
      if (!check_level(c.level, "a cylinder")) return std::nullopt;
    }
    return world;
  }

 private:
  ParseError& error_;
};

}  // namespace

const char* ToString(Material m) {
  switch (m) {
    case Material::kPainted: return "painted";
    case Material::kConcrete: return "concrete";
    case Material::kWood: return "wood";
    case Material::kMetal: return "metal";
    case Material::kFabric: return "fabric";
    case Material::kGlass: return "glass";
  }
  return "?";
}

double Reflectivity(Material m) {
  // Typical VLP-16 calibrated reflectivity of indoor surfaces (0-100 diffuse, 101-255 retro).
  switch (m) {
    case Material::kPainted: return 70;
    case Material::kConcrete: return 35;
    case Material::kWood: return 45;
    case Material::kMetal: return 90;
    case Material::kFabric: return 20;
    case Material::kGlass: return 8;
  }
  return 50;
}

Eigen::Vector2d Room::Centroid() const {
  double a = 0;
  Eigen::Vector2d c(0, 0);
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& p = polygon[i];
    const Eigen::Vector2d& q = polygon[(i + 1) % polygon.size()];
    const double k = Cross(p, q);
    a += k;
    c += (p + q) * k;
  }
  return c / (3.0 * a);
}

double Room::Area() const {
  double a = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i) a += Cross(polygon[i], polygon[(i + 1) % polygon.size()]);
  return 0.5 * std::fabs(a);
}

bool Room::Contains(const Eigen::Vector2d& p) const {
  bool inside = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

const Level* World::FindLevel(int index) const {
  for (const Level& l : levels) {
    if (l.index == index) return &l;
  }
  return nullptr;
}

const Room* World::RoomAt(const Eigen::Vector2d& p, int level) const {
  for (const Room& r : rooms) {
    if (r.level == level && r.Contains(p)) return &r;
  }
  return nullptr;
}

std::optional<World> ParseWorld(const std::string& text, ParseError& error) { return Parser(error).Run(text); }

std::optional<World> LoadWorld(const std::string& path, std::string& error_message) {
  std::ifstream in(path);
  if (!in) {
    error_message = path + ": cannot open";
    return std::nullopt;
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  ParseError error;
  auto world = ParseWorld(buffer.str(), error);
  if (!world) error_message = path + ":" + (error.line > 0 ? std::to_string(error.line) + ": " : " ") + error.reason;
  return world;
}

}  // namespace msgraphs::sim
