// SPDX-License-Identifier: MIT
#include "symmetry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace msgraphs::sim::building {
namespace {

constexpr double kTolerance_m = 1e-6;

bool Near(const Vec2& a, const Vec2& b) { return (a - b).norm() < kTolerance_m; }

template <typename T, typename Same>
bool SameSets(const std::vector<T>& a, const std::vector<T>& b, Same same) {
  if (a.size() != b.size()) return false;
  std::vector<bool> used(b.size(), false);
  for (const T& x : a) {
    bool found = false;
    for (std::size_t i = 0; i < b.size() && !found; ++i) {
      if (!used[i] && same(x, b[i])) found = used[i] = true;
    }
    if (!found) return false;
  }
  return true;
}

struct DoorMark {
  Vec2 centre;
  double width, height;
};

std::vector<DoorMark> DoorsOf(int room, const std::vector<PlacedDoor>& doors) {
  std::vector<DoorMark> out;
  for (const PlacedDoor& d : doors) {
    if (d.a == room || d.b == room) out.push_back({d.centre, d.width_m, d.height_m});
  }
  return out;
}

// Is room `b` room `a` mapped by T: outline, doors and furniture?
bool IsImage(const Plan& plan,
             const std::vector<PlacedDoor>& doors,
             const std::vector<std::vector<Item>>& items,
             int a,
             int b,
             const Affine2& T) {
  const auto& pa = plan.rooms[static_cast<std::size_t>(a)].polygon;
  const auto& pb = plan.rooms[static_cast<std::size_t>(b)].polygon;
  if (!SameSets(pa, pb, [&](const Vec2& x, const Vec2& y) { return Near(T(x), y); })) return false;
  if (!SameSets(DoorsOf(a, doors), DoorsOf(b, doors), [&](const DoorMark& x, const DoorMark& y) {
        return Near(T(x.centre), y.centre) && std::fabs(x.width - y.width) < kTolerance_m &&
               std::fabs(x.height - y.height) < kTolerance_m;
      })) {
    return false;
  }
  return SameSets(items[static_cast<std::size_t>(a)], items[static_cast<std::size_t>(b)],
                  [&](const Item& x, const Item& y) {
                    if (!Near(T(x.centre), y.centre) || x.round != y.round ||
                        x.material != y.material ||
                        std::fabs(x.size_x_m - y.size_x_m) > kTolerance_m ||
                        std::fabs(x.size_y_m - y.size_y_m) > kTolerance_m ||
                        std::fabs(x.height_m - y.height_m) > kTolerance_m) {
                      return false;
                    }
                    return x.round || std::fabs(std::remainder(T.MapAngle(x.yaw_rad) - y.yaw_rad,
                                                               std::numbers::pi)) < 1e-9;
                  });
}

}  // namespace

void KeepVerifiedCopies(Plan& plan,
                        const std::vector<PlacedDoor>& doors,
                        const std::vector<std::vector<Item>>& items) {
  for (auto& group : plan.identical_groups) {
    if (group.empty()) continue;
    const int first = group.front();
    std::vector<int> kept{first};
    for (std::size_t k = 1; k < group.size(); ++k) {
      const int r = group[k];
      const Vec2 shift = plan.rooms[static_cast<std::size_t>(r)].polygon[0] -
                         plan.rooms[static_cast<std::size_t>(first)].polygon[0];
      if (IsImage(plan, doors, items, first, r, Affine2::Translation(shift))) kept.push_back(r);
    }
    group = kept.size() >= 2 ? kept : std::vector<int>{};
  }
  plan.identical_groups.erase(
      std::remove_if(plan.identical_groups.begin(), plan.identical_groups.end(),
                     [](const auto& g) { return g.empty(); }),
      plan.identical_groups.end());
  const Affine2 mirror = Affine2::Reflection(plan.mirror_axis_point, plan.mirror_axis_direction);
  plan.mirror_pairs.erase(
      std::remove_if(
          plan.mirror_pairs.begin(), plan.mirror_pairs.end(),
          [&](const auto& p) { return !IsImage(plan, doors, items, p.first, p.second, mirror); }),
      plan.mirror_pairs.end());
}

}  // namespace msgraphs::sim::building
