// SPDX-License-Identifier: MIT
#include "doors.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

namespace msgraphs::sim::building {
namespace {

constexpr double kEndMargin_m = 0.1;  // solid wall kept at a wall's own ends
constexpr double kDoorGap_m = 0.3;    // solid wall kept between two doors of one wall
constexpr double kMinDoor_m = 0.8;    // narrowest door placed
constexpr double kLintel_m = 0.2;     // thinnest lintel above a door
// A narrow door keeps this much more solid wall beside it (a door frame's return), so that a
// robot coming through has room to turn even next to a corner.
constexpr double kNarrowDoor_m = 1.2;
constexpr double kJambReturn_m = 0.25;

bool IsCirculation(RoomUse u) {
  return u == RoomUse::kCorridor || u == RoomUse::kLobby || u == RoomUse::kHallway;
}

// Clips the convex polygon `poly` to lo <= y <= hi (y = lateral coordinate).
std::vector<Vec2> ClipBand(std::vector<Vec2> poly, double lo, double hi) {
  auto clip = [](const std::vector<Vec2>& in, double bound, double sign) {
    std::vector<Vec2> out;
    for (std::size_t i = 0; i < in.size(); ++i) {
      const Vec2& a = in[i];
      const Vec2& b = in[(i + 1) % in.size()];
      const double da = sign * (bound - a.y()), db = sign * (bound - b.y());  // >= 0 inside
      if (da >= 0) out.push_back(a);
      if ((da >= 0) != (db >= 0)) out.push_back(a + (b - a) * (da / (da - db)));
    }
    return out;
  };
  poly = clip(poly, hi, 1.0);
  if (poly.empty()) return poly;
  return clip(poly, lo, -1.0);
}

}  // namespace

DoorPlacer::DoorPlacer(const Plan& plan, std::vector<PlanWall>& walls)
    : plan_(plan),
      walls_(walls),
      blocked_(walls.size()),
      door_of_connection_(plan.connections.size(), -1) {
  for (std::size_t w = 0; w < walls_.size(); ++w) {
    const Wall& W = walls_[w].wall;
    const Vec2 d = W.direction(), n = W.normal();
    const double band = 0.5 * W.thickness_m + kDoorReach_m;
    for (std::size_t x = 0; x < walls_.size(); ++x) {
      if (x == w) continue;
      const Wall& X = walls_[x].wall;
      // X's footprint as the scene builds it: grown by half its thickness at both ends.
      const Vec2 dx = X.direction(), nx = X.normal();
      const double h = 0.5 * X.thickness_m;
      std::vector<Vec2> local;
      const Vec2 corners[] = {X.start - dx * h - nx * h, X.end + dx * h - nx * h,
                              X.end + dx * h + nx * h, X.start - dx * h + nx * h};
      for (const Vec2& c : corners) {
        local.emplace_back((c - W.start).dot(d), (c - W.start).dot(n));
      }
      const auto clipped = ClipBand(local, -band, band);
      if (clipped.empty()) continue;
      double lo = 1e18, hi = -1e18;
      for (const Vec2& p : clipped) {
        lo = std::min(lo, p.x());
        hi = std::max(hi, p.x());
      }
      blocked_[w].emplace_back(lo - 0.05, hi + 0.05);
    }
  }
}

const PlacedDoor* DoorPlacer::door_of(int connection) const {
  if (connection < 0 || connection >= static_cast<int>(door_of_connection_.size())) return nullptr;
  const int k = door_of_connection_[static_cast<std::size_t>(connection)];
  return k < 0 ? nullptr : &doors_[static_cast<std::size_t>(k)];
}

std::vector<std::pair<double, double>> DoorPlacer::FreeIntervals(int wall,
                                                                 double s0,
                                                                 double s1) const {
  const Wall& W = walls_[static_cast<std::size_t>(wall)].wall;
  std::vector<std::pair<double, double>> blocked = blocked_[static_cast<std::size_t>(wall)];
  blocked.emplace_back(-1e18, kEndMargin_m);
  blocked.emplace_back(W.length() - kEndMargin_m, 1e18);
  for (const Door& d : W.doors)
    blocked.emplace_back(d.offset_m - kDoorGap_m, d.offset_m + d.width_m + kDoorGap_m);
  std::sort(blocked.begin(), blocked.end());
  std::vector<std::pair<double, double>> free;
  double cursor = s0;
  for (const auto& [lo, hi] : blocked) {
    if (lo > cursor) free.emplace_back(cursor, std::min(lo, s1));
    cursor = std::max(cursor, hi);
    if (cursor >= s1) break;
  }
  if (cursor < s1) free.emplace_back(cursor, s1);
  free.erase(std::remove_if(free.begin(), free.end(),
                            [](const auto& f) { return f.second - f.first <= 1e-9; }),
             free.end());
  return free;
}

double DoorPlacer::DoorHeight(const Connection& c) const {
  if (!c.lintel) return plan_.ceiling_m;
  return std::max(1.0, std::min(c.door_height_m, plan_.ceiling_m - kLintel_m));
}

void DoorPlacer::Add(
    int wall, int a, int b, double offset, double width, double height, int index) {
  PlanWall& w = walls_[static_cast<std::size_t>(wall)];
  offset = std::round(offset * 1e4) / 1e4;  // 0.1 mm, like every generated number
  w.wall.doors.push_back({offset, width, height});
  PlacedDoor door;
  door.wall = wall;
  door.a = a;
  door.b = b;
  door.offset_m = offset;
  door.width_m = width;
  door.height_m = height;
  door.centre = w.wall.start + w.wall.direction() * (offset + 0.5 * width);
  bool a_left = false;
  for (const WallSpan& s : w.spans) {
    if (offset + 0.5 * width >= s.s0_m && offset + 0.5 * width <= s.s1_m) a_left = s.left == a;
  }
  door.into_a = a_left ? w.wall.normal() : Vec2(-w.wall.normal());
  if (index >= 0)
    door_of_connection_[static_cast<std::size_t>(index)] = static_cast<int>(doors_.size());
  doors_.push_back(door);
}

int DoorPlacer::ResolveCorridor(int a) const {
  // The corridor sharing the most wall with a (ties: the lower index); other circulation
  // (lobbies, hallways) only when no corridor is next to it.
  std::vector<double> shared(plan_.rooms.size(), 0.0);
  for (const PlanWall& w : walls_) {
    for (const WallSpan& s : w.spans) {
      const int other = s.left == a ? s.right : s.right == a ? s.left : -1;
      if (other < 0) continue;
      const RoomUse use = plan_.rooms[static_cast<std::size_t>(other)].use;
      if (IsCirculation(use))
        shared[static_cast<std::size_t>(other)] +=
            (s.s1_m - s.s0_m) + (use == RoomUse::kCorridor ? 1e4 : 0.0);
    }
  }
  int best = -1;
  for (std::size_t r = 0; r < shared.size(); ++r) {
    if (shared[r] > 1e-9 && (best < 0 || shared[r] > shared[static_cast<std::size_t>(best)] + 1e-9))
      best = static_cast<int>(r);
  }
  return best;
}

bool DoorPlacer::Place(const Connection& c, int index) {
  const int b = c.b >= 0 ? c.b : ResolveCorridor(c.a);
  if (b < 0) return false;
  if (c.follows >= 0) {
    if (const PlacedDoor* original = door_of(c.follows)) {
      Connection same = c;
      same.width_m = original->width_m;  // the original's may have been narrowed to fit
      if (PlaceAt(same, b, c.follow_map(original->centre), index)) return true;
    }
    displaced_.push_back(index);
  }
  // The longest free stretch of wall the two rooms share.
  int best_wall = -1;
  std::pair<double, double> best{0, 0};
  const double jamb = c.width_m < kNarrowDoor_m ? kJambReturn_m : 0.0;
  for (std::size_t w = 0; w < walls_.size(); ++w) {
    for (const WallSpan& s : walls_[w].spans) {
      if (!((s.left == c.a && s.right == b) || (s.left == b && s.right == c.a))) continue;
      for (auto f : FreeIntervals(static_cast<int>(w), s.s0_m, s.s1_m)) {
        f = {f.first + jamb, f.second - jamb};
        if (f.second - f.first > best.second - best.first + 1e-9) {
          best = f;
          best_wall = static_cast<int>(w);
        }
      }
    }
  }
  const double free = best.second - best.first;
  if (best_wall < 0 || free < kMinDoor_m) return false;
  const double width = std::min(c.width_m, std::floor(free * 100.0) / 100.0);
  const double offset = best.first + std::clamp(c.position, 0.0, 1.0) * (free - width);
  Add(best_wall, c.a, b, offset, width, DoorHeight(c), index);
  return true;
}

bool DoorPlacer::PlaceAt(const Connection& c, int b, const Vec2& centre, int index) {
  for (std::size_t w = 0; w < walls_.size(); ++w) {
    const Wall& W = walls_[w].wall;
    if (std::fabs((centre - W.start).dot(W.normal())) > 1e-3) continue;
    const double s = (centre - W.start).dot(W.direction());
    for (const WallSpan& span : walls_[w].spans) {
      if (!((span.left == c.a && span.right == b) || (span.left == b && span.right == c.a)))
        continue;
      if (s < span.s0_m || s > span.s1_m) continue;
      const double lo = s - 0.5 * c.width_m, hi = s + 0.5 * c.width_m;
      const double jamb = c.width_m < kNarrowDoor_m ? kJambReturn_m : 0.0;
      for (const auto& f : FreeIntervals(static_cast<int>(w), span.s0_m, span.s1_m)) {
        if (lo >= f.first + jamb - 1e-9 && hi <= f.second - jamb + 1e-9) {
          Add(static_cast<int>(w), c.a, b, lo, c.width_m, DoorHeight(c), index);
          return true;
        }
      }
    }
  }
  return false;
}

void DoorPlacer::PlaceAll() {
  // Originals first, then the doors that copy them.
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 0; i < plan_.connections.size(); ++i) {
      const Connection& c = plan_.connections[i];
      if ((c.follows >= 0) != (pass == 1)) continue;
      if (!Place(c, static_cast<int>(i))) failed_.push_back(static_cast<int>(i));
    }
  }
}

bool DoorPlacer::ConnectAll(std::string& error) {
  const std::size_t n = plan_.rooms.size();
  for (;;) {
    std::vector<bool> reached(n, false);
    std::deque<int> queue{0};
    reached[0] = true;
    while (!queue.empty()) {
      const int r = queue.front();
      queue.pop_front();
      for (const PlacedDoor& d : doors_) {
        const int other = d.a == r ? d.b : d.b == r ? d.a : -1;
        if (other >= 0 && !reached[static_cast<std::size_t>(other)]) {
          reached[static_cast<std::size_t>(other)] = true;
          queue.push_back(other);
        }
      }
    }
    int lonely = -1;
    for (std::size_t r = 0; r < n && lonely < 0; ++r) {
      if (!reached[r]) lonely = static_cast<int>(r);
    }
    if (lonely < 0) return true;
    // Its reached neighbours, circulation first, then by shared length.
    std::vector<std::pair<double, int>> candidates;
    for (const PlanWall& w : walls_) {
      for (const WallSpan& s : w.spans) {
        const int other = s.left == lonely ? s.right : s.right == lonely ? s.left : -1;
        if (other < 0 || !reached[static_cast<std::size_t>(other)]) continue;
        const double bonus =
            IsCirculation(plan_.rooms[static_cast<std::size_t>(other)].use) ? 1000.0 : 0.0;
        candidates.emplace_back(bonus + s.s1_m - s.s0_m, other);
      }
    }
    std::sort(candidates.begin(), candidates.end(), [](const auto& x, const auto& y) {
      return x.first > y.first || (x.first == y.first && x.second < y.second);
    });
    bool placed = false;
    for (const auto& [score, other] : candidates) {
      Connection c;
      c.a = lonely;
      c.b = other;
      c.width_m = 0.9;
      if (Place(c, -1)) {
        placed = true;
        break;
      }
    }
    if (!placed) {
      error = "room " + std::to_string(lonely) + " cannot be given a door";
      return false;
    }
  }
}

}  // namespace msgraphs::sim::building
