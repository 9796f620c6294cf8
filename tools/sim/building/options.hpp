// SPDX-License-Identifier: MIT
// What a generated building may be: its style, corridor shape, symmetric variant, rotation,
// wing angle and clutter. A BuildingOptions field left empty is drawn from the seed; a set one
// forces that choice (tests and benchmarks that need a specific case). docs/simulator.md.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace msgraphs::sim::building {

enum class Style : std::uint8_t {
  kOffice,        ///< office or school: double-loaded corridors, rows of rooms, open-plan halls
  kHospital,      ///< identical patient rooms with en-suite bathrooms, often mirrored wings
  kWarehouse,     ///< large halls with rack rows, a strip of offices along a corridor
  kConstruction,  ///< bare concrete rooms and halls, columns, wide openings without lintels
  kApartment,     ///< flats of small rooms (down to 2 x 2 m) off a corridor
  kMultiWing,     ///< wings of double-loaded corridors meeting at 30, 45, 60 or 90 degrees
};
inline constexpr int kStyleCount = 6;

enum class CorridorShape : std::uint8_t { kNone, kStraight, kL, kT, kU, kLoop };
enum class Symmetry : std::uint8_t { kNone, kIdenticalRow, kMirroredWings, kBoth };
enum class Clutter : std::uint8_t { kNone, kSparse, kMedium, kDense };

const char* ToString(Style s);
const char* ToString(CorridorShape s);
const char* ToString(Symmetry s);
const char* ToString(Clutter c);
/// Name -> value ("office", "loop", "mirrored-wings", "dense", ...); false for unknown names.
bool Parse(const std::string& name, Style& out);
bool Parse(const std::string& name, CorridorShape& out);
bool Parse(const std::string& name, Symmetry& out);
bool Parse(const std::string& name, Clutter& out);

struct BuildingOptions {
  std::optional<Style> style;
  /// Corridor shape of the main block (office, hospital, apartment); kNone is refused there.
  std::optional<CorridorShape> corridor;
  std::optional<Symmetry> symmetry;
  /// The whole building's rotation about its centre, degrees.
  std::optional<double> rotation_deg;
  /// Turn between neighbouring wings, degrees (multi-wing and mirrored-wing buildings): 0
  /// (straight on), 30, 45, 60 or 90.
  std::optional<double> wing_angle_deg;
  std::optional<Clutter> clutter;
  /// Level ceiling height (= wall height), 2.3 .. 6 m.
  std::optional<double> ceiling_m;
};

/// Checks forced values (ranges, style and shape combinations). Empty string when fine.
std::string CheckOptions(const BuildingOptions& options);

/// Whether `flag` is one of the command-line options below.
bool IsOption(const std::string& flag);
/// Sets one command-line option ("--style office", "--corridor loop", "--symmetry both",
/// "--rotation-deg 30", "--wing-angle-deg 45", "--clutter dense", "--ceiling-m 2.3").
/// False with `error` for an unknown value.
bool SetOption(const std::string& flag,
               const std::string& value,
               BuildingOptions& options,
               std::string& error);

}  // namespace msgraphs::sim::building
