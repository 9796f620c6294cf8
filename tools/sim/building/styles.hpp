// SPDX-License-Identifier: MIT
// The building styles: each turns resolved choices and a random stream into a Plan (rooms
// and the doors wanted between them). One style per file (style_*.cpp).
#pragma once

#include <string>

#include "options.hpp"
#include "plan.hpp"
#include "random.hpp"

namespace msgraphs::sim::building {

/// Every option resolved: forced by the caller or drawn from the seed.
struct Choices {
  Style style = Style::kOffice;
  CorridorShape corridor = CorridorShape::kStraight;
  Symmetry symmetry = Symmetry::kNone;
  double rotation_deg = 0;
  double wing_angle_deg = 0;
  bool wing_angle_forced = false;
  Clutter clutter = Clutter::kMedium;
  double ceiling_m = 3.0;
  /// Lengths are scaled by this after failed attempts (too many rooms, too large).
  double scale = 1.0;

  bool identical_rows() const {
    return symmetry == Symmetry::kIdenticalRow || symmetry == Symmetry::kBoth;
  }
  bool mirrored_wings() const {
    return symmetry == Symmetry::kMirroredWings || symmetry == Symmetry::kBoth;
  }
};

bool BuildOffice(const Choices& c, Random& rng, Plan& plan, std::string& error);
bool BuildHospital(const Choices& c, Random& rng, Plan& plan, std::string& error);
bool BuildWarehouse(const Choices& c, Random& rng, Plan& plan, std::string& error);
bool BuildConstruction(const Choices& c, Random& rng, Plan& plan, std::string& error);
bool BuildApartment(const Choices& c, Random& rng, Plan& plan, std::string& error);
bool BuildMultiWing(const Choices& c, Random& rng, Plan& plan, std::string& error);

inline bool BuildStyle(const Choices& c, Random& rng, Plan& plan, std::string& error) {
  switch (c.style) {
    case Style::kOffice:
      return BuildOffice(c, rng, plan, error);
    case Style::kHospital:
      return BuildHospital(c, rng, plan, error);
    case Style::kWarehouse:
      return BuildWarehouse(c, rng, plan, error);
    case Style::kConstruction:
      return BuildConstruction(c, rng, plan, error);
    case Style::kApartment:
      return BuildApartment(c, rng, plan, error);
    case Style::kMultiWing:
      return BuildMultiWing(c, rng, plan, error);
  }
  error = "unknown style";
  return false;
}

}  // namespace msgraphs::sim::building
