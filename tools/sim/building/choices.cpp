// SPDX-License-Identifier: MIT
#include "choices.hpp"

#include <cmath>
#include <initializer_list>
#include <vector>

#include "random.hpp"

namespace msgraphs::sim::building {
namespace {

enum Draw : std::uint64_t { kStyle = 1, kCorridor, kSymmetry, kRotation, kClutter, kCeiling };
constexpr std::uint64_t kChoiceStream = 0x63686F6F;  // "choo"

template <typename T>
T PickFrom(Random& rng, std::initializer_list<T> values, std::initializer_list<double> weights) {
  double total = 0;
  for (double w : weights) total += w;
  double u = rng.Uniform() * total;
  auto value = values.begin();
  for (double w : weights) {
    if (u < w || value + 1 == values.end()) return *value;
    u -= w;
    ++value;
  }
  return *value;
}

}  // namespace

Choices Resolve(std::uint64_t seed, const BuildingOptions& o) {
  bool ok = CheckOptions(o).empty();
  auto stream = [&](Draw d) { return Random::Stream(seed, kChoiceStream, d); };
  Choices c;

  // Style: forced, or drawn among the styles that can honour the other forced options.
  {
    Random rng = stream(kStyle);
    std::vector<Style> styles;
    for (int s = 0; s < kStyleCount; ++s) {
      BuildingOptions probe = o;
      probe.style = static_cast<Style>(s);
      if (!ok || CheckOptions(probe).empty()) styles.push_back(static_cast<Style>(s));
    }
    if (styles.empty()) {  // the forced options exclude each other: draw as if none were given
      ok = false;
      for (int s = 0; s < kStyleCount; ++s) styles.push_back(static_cast<Style>(s));
    }
    if (o.style && ok) {
      c.style = *o.style;
    } else {
      c.style = styles[static_cast<std::size_t>(rng.Index(static_cast<int>(styles.size())))];
    }
  }
  const bool forced_ok = ok;
  const bool corridors =
      c.style == Style::kOffice || c.style == Style::kHospital || c.style == Style::kApartment;
  {
    Random rng = stream(kSymmetry);
    using S = Symmetry;
    switch (c.style) {
      case Style::kOffice:
        c.symmetry = PickFrom(rng, {S::kNone, S::kIdenticalRow, S::kMirroredWings, S::kBoth},
                              {0.5, 0.3, 0.1, 0.1});
        break;
      case Style::kHospital:
        c.symmetry = PickFrom(rng, {S::kNone, S::kIdenticalRow, S::kMirroredWings, S::kBoth},
                              {0.1, 0.4, 0.1, 0.4});
        break;
      case Style::kApartment:
        c.symmetry = PickFrom(rng, {S::kNone, S::kIdenticalRow}, {0.6, 0.4});
        break;
      case Style::kMultiWing:
        c.symmetry = PickFrom(rng, {S::kNone, S::kIdenticalRow, S::kMirroredWings, S::kBoth},
                              {0.4, 0.2, 0.25, 0.15});
        break;
      default:
        c.symmetry = S::kNone;
    }
    if (forced_ok && o.symmetry) c.symmetry = *o.symmetry;
  }
  {
    Random rng = stream(kCorridor);
    using C = CorridorShape;
    if (!corridors) {
      c.corridor = c.style == Style::kConstruction ? C::kNone : C::kStraight;
    } else if (c.mirrored_wings()) {
      c.corridor = C::kStraight;
    } else if (c.style == Style::kApartment) {
      c.corridor = PickFrom(rng, {C::kStraight, C::kL, C::kT}, {0.6, 0.25, 0.15});
    } else {
      c.corridor =
          PickFrom(rng, {C::kStraight, C::kL, C::kT, C::kU, C::kLoop}, {0.3, 0.2, 0.15, 0.15, 0.2});
    }
    if (forced_ok && o.corridor && corridors) c.corridor = *o.corridor;
  }
  {
    Random rng = stream(kRotation);
    // A quarter of the buildings square to the world axes, the rest at any angle (0.1 deg).
    c.rotation_deg =
        rng.Chance(0.25) ? 90.0 * rng.Index(4) : std::round(rng.Uniform(0, 3600)) / 10.0;
    if (o.rotation_deg && std::isfinite(*o.rotation_deg)) c.rotation_deg = *o.rotation_deg;
  }
  if (forced_ok && o.wing_angle_deg) {
    c.wing_angle_deg = *o.wing_angle_deg;
    c.wing_angle_forced = true;
  }
  {
    Random rng = stream(kClutter);
    using K = Clutter;
    c.clutter =
        PickFrom(rng, {K::kNone, K::kSparse, K::kMedium, K::kDense}, {0.15, 0.3, 0.35, 0.2});
    if (o.clutter) c.clutter = *o.clutter;
  }
  {
    Random rng = stream(kCeiling);
    static const std::vector<double> kOffice = {2.6, 2.7, 2.8, 3.0, 3.2, 3.5};
    static const std::vector<double> kHospital = {2.7, 2.8, 3.0, 3.2};
    static const std::vector<double> kWarehouse = {4.5, 5.0, 5.5, 6.0};
    static const std::vector<double> kConstruction = {3.0, 3.2, 3.5, 4.0, 4.5};
    static const std::vector<double> kApartment = {2.3, 2.4, 2.5, 2.6, 2.7};
    const std::vector<double>* set = &kOffice;
    switch (c.style) {
      case Style::kHospital:
        set = &kHospital;
        break;
      case Style::kWarehouse:
        set = &kWarehouse;
        break;
      case Style::kConstruction:
        set = &kConstruction;
        break;
      case Style::kApartment:
        set = &kApartment;
        break;
      default:
        break;
    }
    c.ceiling_m = (*set)[static_cast<std::size_t>(rng.Index(static_cast<int>(set->size())))];
    if (o.ceiling_m && *o.ceiling_m >= 2.3 && *o.ceiling_m <= 6.0) c.ceiling_m = *o.ceiling_m;
  }
  return c;
}

}  // namespace msgraphs::sim::building
