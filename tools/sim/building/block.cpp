// SPDX-License-Identifier: MIT
#include "block.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::sim::building {
namespace {
constexpr double kEndFrontage_m = 1.9;  // a 1.4 m door and its jambs
}  // namespace

Rect Strip::Piece(double along0, double along1, double depth0, double depth1) const {
  switch (front) {
    case 0:
      return {along0, rect.y0 + depth0, along1, rect.y0 + depth1};
    case 2:
      return {along0, rect.y1 - depth1, along1, rect.y1 - depth0};
    case 3:
      return {rect.x0 + depth0, along0, rect.x0 + depth1, along1};
    default:
      return {rect.x1 - depth1, along0, rect.x1 - depth0, along1};
  }
}

CorridorLayout LayoutCorridors(const CorridorSpec& s) {
  CorridorLayout out;
  const double w = s.width_m, X = s.length_m, Y = s.arm_m;
  const double Ds = s.depth_s_m, Dn = s.depth_n_m, De = s.depth_e_m, Dw = s.depth_w_m,
               Di = s.depth_in_m;
  auto strip = [&](double x0, double y0, double x1, double y1, int front, double f0, double f1,
                   bool core = false) {
    out.strips.push_back(
        {{SnapCm(x0), SnapCm(y0), SnapCm(x1), SnapCm(y1)}, front, SnapCm(f0), SnapCm(f1), core});
  };
  auto rect = [](double x0, double y0, double x1, double y1) {
    return Rect{SnapCm(x0), SnapCm(y0), SnapCm(x1), SnapCm(y1)};
  };
  switch (s.shape) {
    case CorridorShape::kNone:
      break;
    case CorridorShape::kStraight: {
      if (s.split) {
        const double cut = SnapCm(0.5 * X);
        out.corridors = {{rect(0, 0, cut, w)}, {rect(cut, 0, X, w)}};
        out.joints = {{0, 1}};
        out.west_end = 0;
        out.east_end = 1;
      } else {
        out.corridors = {{rect(0, 0, X, w)}};
        out.west_end = out.east_end = 0;
      }
      strip(0, -Ds, X, 0, 2, 0, X);
      strip(0, w, X, w + Dn, 0, 0, X);
      out.y_lo = -Ds;
      out.y_hi = w + Dn;
      break;
    }
    case CorridorShape::kL: {
      const Rect a = rect(0, 0, X, w), corner = rect(X, 0, X + w, w), b = rect(X, w, X + w, w + Y);
      if (s.split) {
        out.corridors = {{a}, {corner, b}};
        out.joints = {{0, 1}};
      } else {
        out.corridors = {{a, corner, b}};
      }
      strip(0, -Ds, X + w + De, 0, 2, 0, X + w);
      strip(X + w, 0, X + w + De, w + Y, 3, 0, w + Y);
      strip(0, w, X, w + Dn, 0, 0, X);
      strip(X - Dw, w + Dn, X, w + Y, 1, w + Dn, w + Y);
      break;
    }
    case CorridorShape::kT: {
      const double xb = s.branch_at_m;
      const Rect main = rect(0, 0, X, w), branch = rect(xb, w, xb + w, w + Y);
      if (s.split) {
        out.corridors = {{main}, {branch}};
        out.joints = {{0, 1}};
      } else {
        out.corridors = {{main, branch}};
      }
      strip(0, -Ds, X, 0, 2, 0, X);
      strip(0, w, xb, w + Dn, 0, 0, xb);
      strip(xb + w, w, X, w + Dn, 0, xb + w, X);
      strip(xb - Dw, w + Dn, xb, w + Y, 1, w + Dn, w + Y);
      strip(xb + w, w + Dn, xb + w + De, w + Y, 3, w + Dn, w + Y);
      break;
    }
    case CorridorShape::kU: {
      const Rect main = rect(0, 0, X, w), west = rect(0, w, w, w + Y),
                 east = rect(X - w, w, X, w + Y);
      if (s.split) {
        out.corridors = {{main}, {west}, {east}};
        out.joints = {{0, 1}, {0, 2}};
      } else {
        out.corridors = {{main, west, east}};
      }
      strip(-Dw, -Ds, X + De, 0, 2, 0, X);
      strip(-Dw, 0, 0, w + Y, 1, 0, w + Y);
      strip(X, 0, X + De, w + Y, 3, 0, w + Y);
      strip(w, w, X - w, w + Dn, 0, w, X - w);
      strip(w, w + Dn, w + Di, w + Y, 3, w + Dn, w + Y);
      strip(X - w - Di, w + Dn, X - w, w + Y, 1, w + Dn, w + Y);
      break;
    }
    case CorridorShape::kLoop: {
      // A ring round a core; its outer edge is [0, X] x [0, Y].
      const Rect bottom = rect(0, 0, X, w), top = rect(0, Y - w, X, Y);
      const Rect left = rect(0, w, w, Y - w), right = rect(X - w, w, X, Y - w);
      if (s.split) {
        out.corridors = {{bottom}, {right}, {top}, {left}};
        out.joints = {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
      } else {
        // Two L-shaped halves (a ring is no simple polygon), open to each other at two ends.
        out.corridors = {{bottom, right}, {top, left}};
        out.joints = {{0, 1}, {0, 1}};
      }
      strip(-Dw, -Ds, X + De, 0, 2, 0, X);
      strip(-Dw, Y, X + De, Y + Dn, 0, 0, X);
      strip(-Dw, 0, 0, Y, 1, 0, Y);
      strip(X, 0, X + De, Y, 3, 0, Y);
      const double core = Y - 2 * w;
      if (core >= 2 * 4.0) {
        const double mid = SnapCm(w + 0.5 * core);
        strip(w, w, X - w, mid, 0, w, X - w, true);
        strip(w, mid, X - w, Y - w, 2, w, X - w, true);
      } else {
        strip(w, w, X - w, Y - w, 0, w, X - w, true);
      }
      break;
    }
  }
  return out;
}

std::vector<std::pair<double, double>> CutStrip(
    const Strip& s, Random& rng, double min_m, double max_m, double frontage_m) {
  std::vector<std::pair<double, double>> out;
  const double a0 = s.a0(), a1 = s.a1();
  double cursor = a0;
  while (cursor < a1 - 1e-9) {
    double next = SnapCm(cursor + rng.Uniform(min_m, max_m));
    next = std::max(next, SnapCm(s.f0 + frontage_m));  // the first room reaches the frontage
    // The rest is too short for a room, or would not face the corridor: take it all.
    if (a1 - next < min_m || next > s.f1 - frontage_m) next = a1;
    out.emplace_back(cursor, next);
    cursor = next;
  }
  return out;
}

std::vector<std::pair<double, double>> CutIdentical(
    const Strip& s, double width_m, double end_min_m, int& first, int& count) {
  const double frontage = s.f1 - s.f0;
  const bool lo_end = s.f0 - s.a0() > 1e-6,
             hi_end = s.a1() - s.f1 > 1e-6;  // strip beyond the corridor
  std::vector<std::pair<double, double>> out;
  for (int n = static_cast<int>(std::floor(frontage / width_m)); n >= 2; --n) {
    const double rest = frontage - n * width_m;
    if (!lo_end && !hi_end) {
      // The row fills the strip: the rooms stretch to share the rest (all still identical).
      const double w = frontage / n;
      for (int k = 0; k < n; ++k) {
        out.emplace_back(k == 0 ? s.a0() : out.back().second,
                         k + 1 == n ? s.a1() : s.a0() + (k + 1) * w);
      }
      first = 0;
      count = n;
      return out;
    }
    // An end room on each side that has strip beyond the corridor takes the rest there (and
    // needs enough corridor in front of it for a door).
    const int ends = (lo_end ? 1 : 0) + (hi_end ? 1 : 0);
    const double share = rest / ends;
    const double lo_len = s.f0 - s.a0() + share, hi_len = s.a1() - s.f1 + share;
    if (share < kEndFrontage_m || (lo_end && lo_len < end_min_m) || (hi_end && hi_len < end_min_m))
      continue;
    const double start = lo_end ? SnapCm(s.f0 + share) : s.a0();
    if (lo_end) out.emplace_back(s.a0(), start);
    first = static_cast<int>(out.size());
    for (int k = 0; k < n; ++k) {
      const double end = k + 1 == n && !hi_end ? s.a1() : SnapCm(start + (k + 1) * width_m);
      out.emplace_back(k == 0 ? start : out.back().second, end);
    }
    if (hi_end) out.emplace_back(out.back().second, s.a1());
    count = n;
    return out;
  }
  return {};
}

int PlanBuilder::Room(RoomUse use, const std::vector<Rect>& rects) {
  const auto outline = UnionOutline(rects);
  if (!outline) {
    // Not one simple polygon: a layout bug. Keep the first piece so that indices stay valid
    // and have the attempt drawn again.
    plan_.broken = true;
    return RoomPolygon(use, rects.front().ToPolygon());
  }
  return RoomPolygon(use, *outline);
}

int PlanBuilder::RoomPolygon(RoomUse use, const Polygon& block_polygon) {
  PlanRoom room;
  room.use = use;
  room.polygon = Transformed(block_polygon, T_);
  plan_.rooms.push_back(std::move(room));
  return static_cast<int>(plan_.rooms.size()) - 1;
}

int PlanBuilder::Connect(int a, int b, const Connection& door) {
  Connection c = door;
  c.a = a;
  c.b = b;
  plan_.connections.push_back(c);
  return static_cast<int>(plan_.connections.size()) - 1;
}

Connection DrawDoor(Random& rng, DoorKind kind, double no_lintel_chance) {
  static constexpr double kSingle[] = {0.8, 0.9, 1.0};
  static constexpr double kBed[] = {1.1, 1.2, 1.3, 1.4};
  static constexpr double kDouble[] = {1.4, 1.6, 1.8};
  static constexpr double kWide[] = {1.8, 2.0, 2.2, 2.4, 2.5};
  static constexpr double kHeights[] = {2.0, 2.1, 2.2};
  Connection c;
  c.door_height_m = kHeights[rng.Index(3)];
  c.position = rng.Uniform();
  switch (kind) {
    case DoorKind::kSingle:
      c.width_m = kSingle[rng.Index(3)];
      break;
    case DoorKind::kBed:
      c.width_m = kBed[rng.Index(4)];
      break;
    case DoorKind::kDouble:
      c.width_m = kDouble[rng.Index(3)];
      break;
    case DoorKind::kWide:
      c.width_m = kWide[rng.Index(5)];
      c.door_height_m = 2.2 + 0.4 * rng.Index(3);
      break;
    case DoorKind::kOpening:  // as wide as the shared wall allows (corridor joints)
      c.width_m = 2.5;
      c.door_height_m = 2.2 + 0.2 * rng.Index(3);
      c.position = 0.5;
      break;
  }
  c.lintel = !rng.Chance(no_lintel_chance);
  return c;
}

}  // namespace msgraphs::sim::building
