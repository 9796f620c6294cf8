// SPDX-License-Identifier: MIT
#include "options.hpp"

#include <cmath>
#include <cstdlib>

namespace msgraphs::sim::building {
namespace {

template <typename E, std::size_t N>
bool Lookup(const std::string& name, const char* const (&names)[N], E& out) {
  for (std::size_t i = 0; i < N; ++i) {
    if (name == names[i]) {
      out = static_cast<E>(i);
      return true;
    }
  }
  return false;
}

constexpr const char* kStyles[] = {"office",       "hospital",  "warehouse",
                                   "construction", "apartment", "multi-wing"};
constexpr const char* kShapes[] = {"none", "straight", "L", "T", "U", "loop"};
constexpr const char* kSymmetries[] = {"none", "identical-row", "mirrored-wings", "both"};
constexpr const char* kClutters[] = {"none", "sparse", "medium", "dense"};

bool Number(const std::string& s, double& out) {
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0' && std::isfinite(out);
}

}  // namespace

const char* ToString(Style s) { return kStyles[static_cast<int>(s)]; }
const char* ToString(CorridorShape s) { return kShapes[static_cast<int>(s)]; }
const char* ToString(Symmetry s) { return kSymmetries[static_cast<int>(s)]; }
const char* ToString(Clutter c) { return kClutters[static_cast<int>(c)]; }
bool Parse(const std::string& name, Style& out) { return Lookup(name, kStyles, out); }
bool Parse(const std::string& name, CorridorShape& out) { return Lookup(name, kShapes, out); }
bool Parse(const std::string& name, Symmetry& out) { return Lookup(name, kSymmetries, out); }
bool Parse(const std::string& name, Clutter& out) { return Lookup(name, kClutters, out); }

std::string CheckOptions(const BuildingOptions& o) {
  if (o.rotation_deg && !std::isfinite(*o.rotation_deg))
    return "rotation must be a finite number of degrees";
  if (o.ceiling_m && !(*o.ceiling_m >= 2.3 && *o.ceiling_m <= 6.0))
    return "ceiling height must be 2.3 .. 6 m";
  if (o.wing_angle_deg) {
    const double a = *o.wing_angle_deg;
    if (a != 0 && a != 30 && a != 45 && a != 60 && a != 90)
      return "wing angle must be 0, 30, 45, 60 or 90 degrees";
  }
  const bool rows =
      o.symmetry && (*o.symmetry == Symmetry::kIdenticalRow || *o.symmetry == Symmetry::kBoth);
  const bool mirror =
      o.symmetry && (*o.symmetry == Symmetry::kMirroredWings || *o.symmetry == Symmetry::kBoth);
  if (o.corridor && *o.corridor == CorridorShape::kNone)
    return "corridor shape 'none' is not a choice (warehouse and construction have no corridor "
           "shape to force)";
  if (mirror && o.corridor && *o.corridor != CorridorShape::kStraight) {
    return "mirrored wings are straight corridors (a hub and its wings)";
  }
  if (!o.style) return "";
  const Style s = *o.style;
  const bool corridors = s == Style::kOffice || s == Style::kHospital || s == Style::kApartment;
  if (o.corridor && !corridors)
    return std::string("a ") + ToString(s) + " building has no corridor shape to choose";
  if (o.corridor && s == Style::kApartment &&
      (*o.corridor == CorridorShape::kU || *o.corridor == CorridorShape::kLoop)) {
    return "apartment blocks take straight, L or T corridors";
  }
  if ((rows || mirror) && (s == Style::kWarehouse || s == Style::kConstruction)) {
    return std::string("a ") + ToString(s) + " building has no symmetric variant";
  }
  if (mirror && s == Style::kApartment) return "apartment blocks have no mirrored wings";
  if (o.wing_angle_deg &&
      !(s == Style::kMultiWing || ((s == Style::kOffice || s == Style::kHospital) && mirror))) {
    return "a wing angle needs a multi-wing building or mirrored wings";
  }
  return "";
}

bool IsOption(const std::string& flag) {
  for (const char* f : {"--style", "--corridor", "--symmetry", "--clutter", "--rotation-deg",
                        "--wing-angle-deg", "--ceiling-m"}) {
    if (flag == f) return true;
  }
  return false;
}

bool SetOption(const std::string& flag,
               const std::string& value,
               BuildingOptions& o,
               std::string& error) {
  double v = 0;
  if (flag == "--style") {
    Style s{};
    if (!Parse(value, s))
      return error = "unknown style '" + value +
                     "' (office, hospital, warehouse, construction, apartment, multi-wing)",
             false;
    o.style = s;
  } else if (flag == "--corridor") {
    CorridorShape s{};
    if (!Parse(value, s))
      return error = "unknown corridor shape '" + value + "' (straight, L, T, U, loop)", false;
    o.corridor = s;
  } else if (flag == "--symmetry") {
    Symmetry s{};
    if (!Parse(value, s))
      return error = "unknown symmetry '" + value + "' (none, identical-row, mirrored-wings, both)",
             false;
    o.symmetry = s;
  } else if (flag == "--clutter") {
    Clutter c{};
    if (!Parse(value, c))
      return error = "unknown clutter '" + value + "' (none, sparse, medium, dense)", false;
    o.clutter = c;
  } else if (flag == "--rotation-deg" || flag == "--wing-angle-deg" || flag == "--ceiling-m") {
    if (!Number(value, v)) return error = flag + " needs a number", false;
    (flag == "--rotation-deg"     ? o.rotation_deg
     : flag == "--wing-angle-deg" ? o.wing_angle_deg
                                  : o.ceiling_m) = v;
  } else {
    error = "unknown option " + flag;
    return false;
  }
  return true;
}

}  // namespace msgraphs::sim::building
