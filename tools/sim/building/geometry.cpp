// SPDX-License-Identifier: MIT
#include "geometry.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace msgraphs::sim::building {

double SnapCm(double v) { return std::round(v * 100.0) / 100.0; }

Polygon Rect::ToPolygon() const { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

Affine2 Affine2::Rotation(double angle_rad, const Vec2& about) {
  Affine2 T;
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  T.linear << c, -s, s, c;
  T.offset = about - T.linear * about;
  return T;
}

Affine2 Affine2::Translation(const Vec2& t) {
  Affine2 T;
  T.offset = t;
  return T;
}

Affine2 Affine2::Reflection(const Vec2& point, const Vec2& direction) {
  // I - 2 n n^T with n the line's normal.
  const Vec2 n(-direction.y(), direction.x());
  Affine2 T;
  T.linear = Eigen::Matrix2d::Identity() - 2.0 * n * n.transpose();
  T.offset = point - T.linear * point;
  return T;
}

double Affine2::MapAngle(double angle_rad) const {
  const Vec2 d = linear * Vec2(std::cos(angle_rad), std::sin(angle_rad));
  return std::atan2(d.y(), d.x());
}

double Cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

double SignedArea(const Polygon& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) a += Cross(p[i], p[(i + 1) % p.size()]);
  return 0.5 * a;
}

Polygon Normalised(Polygon p) {
  if (SignedArea(p) < 0) std::reverse(p.begin(), p.end());
  // Drop vertices on the straight line between their neighbours (1e-9 m off at most).
  for (bool changed = true; changed && p.size() > 3;) {
    changed = false;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Vec2& a = p[(i + p.size() - 1) % p.size()];
      const Vec2& b = p[(i + 1) % p.size()];
      const double len = (b - a).norm();
      if (len > 0 && std::fabs(Cross(b - a, p[i] - a)) / len < 1e-9 && (p[i] - a).dot(b - a) > 0 &&
          (p[i] - b).dot(a - b) > 0) {
        p.erase(p.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
        break;
      }
    }
  }
  std::size_t first = 0;
  for (std::size_t i = 1; i < p.size(); ++i) {
    if (p[i].y() < p[first].y() - 1e-9 ||
        (std::fabs(p[i].y() - p[first].y()) <= 1e-9 && p[i].x() < p[first].x())) {
      first = i;
    }
  }
  std::rotate(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(first), p.end());
  return p;
}

Polygon Transformed(const Polygon& p, const Affine2& T) {
  Polygon out;
  out.reserve(p.size());
  for (const Vec2& v : p) out.push_back(T(v));
  return Normalised(std::move(out));
}

bool Inside(const Polygon& poly, const Vec2& p) {
  bool inside = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

double SegmentDistance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

std::optional<Polygon> UnionOutline(const std::vector<Rect>& rects) {
  std::vector<double> xs, ys;
  for (const Rect& r : rects) {
    xs.insert(xs.end(), {r.x0, r.x1});
    ys.insert(ys.end(), {r.y0, r.y1});
  }
  auto unique = [](std::vector<double>& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end(), [](double a, double b) { return b - a < 1e-9; }),
            v.end());
  };
  unique(xs);
  unique(ys);
  const int nx = static_cast<int>(xs.size()) - 1, ny = static_cast<int>(ys.size()) - 1;
  if (nx < 1 || ny < 1) return std::nullopt;
  auto inside = [&](int i, int j) {
    if (i < 0 || j < 0 || i >= nx || j >= ny) return false;
    const auto x = static_cast<std::size_t>(i), y = static_cast<std::size_t>(j);
    const Vec2 c(0.5 * (xs[x] + xs[x + 1]), 0.5 * (ys[y] + ys[y + 1]));
    return std::any_of(rects.begin(), rects.end(), [&](const Rect& r) { return r.Contains(c); });
  };
  // Directed boundary edges between grid vertices, interior on the left; keyed (row, column)
  // so that the walk starts at the lowest, then leftmost vertex.
  using Key = std::pair<int, int>;  // (j, i)
  std::map<Key, Key> next;
  bool pinched = false;
  auto add = [&](Key a, Key b) { pinched |= !next.emplace(a, b).second; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      if (!inside(i, j)) continue;
      if (!inside(i, j - 1)) add({j, i}, {j, i + 1});
      if (!inside(i + 1, j)) add({j, i + 1}, {j + 1, i + 1});
      if (!inside(i, j + 1)) add({j + 1, i + 1}, {j + 1, i});
      if (!inside(i - 1, j)) add({j + 1, i}, {j, i});
    }
  }
  if (pinched || next.empty()) return std::nullopt;
  Polygon outline;
  const Key start = next.begin()->first;
  Key at = start;
  std::size_t steps = 0;
  do {
    outline.emplace_back(xs[static_cast<std::size_t>(at.second)],
                         ys[static_cast<std::size_t>(at.first)]);
    at = next.at(at);
    ++steps;
  } while (at != start && steps <= next.size());
  if (steps != next.size()) return std::nullopt;  // more than one loop: split or holed
  return Normalised(std::move(outline));
}

}  // namespace msgraphs::sim::building
