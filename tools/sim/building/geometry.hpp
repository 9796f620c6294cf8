// SPDX-License-Identifier: MIT
// Plane geometry for the building generator: axis-aligned rectangles in a block's frame,
// rigid or mirroring maps between frames, and simple polygons (counter-clockwise).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace msgraphs::sim::building {

using Vec2 = Eigen::Vector2d;
using Polygon = std::vector<Vec2>;

/// Block-frame layout values are kept on a 1 cm grid so that equal sums compare equal.
double SnapCm(double v);

struct Rect {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  double width() const { return x1 - x0; }
  double height() const { return y1 - y0; }
  Vec2 centre() const { return {0.5 * (x0 + x1), 0.5 * (y0 + y1)}; }
  bool Contains(const Vec2& p) const {
    return p.x() > x0 && p.x() < x1 && p.y() > y0 && p.y() < y1;
  }
  Polygon ToPolygon() const;  ///< counter-clockwise, from (x0, y0)
};

/// p -> linear * p + offset; linear is a rotation, or a rotation composed with a reflection.
struct Affine2 {
  Eigen::Matrix2d linear = Eigen::Matrix2d::Identity();
  Vec2 offset = Vec2::Zero();

  static Affine2 Rotation(double angle_rad, const Vec2& about = Vec2::Zero());
  static Affine2 Translation(const Vec2& t);
  /// The reflection about the line through `point` along `direction` (unit).
  static Affine2 Reflection(const Vec2& point, const Vec2& direction);
  Vec2 operator()(const Vec2& p) const { return linear * p + offset; }
  Affine2 operator*(const Affine2& o) const {
    return {linear * o.linear, linear * o.offset + offset};
  }
  bool Mirrors() const { return linear.determinant() < 0; }
  /// The image of a direction given by its angle.
  double MapAngle(double angle_rad) const;
};

double Cross(const Vec2& a, const Vec2& b);
double SignedArea(const Polygon& p);
/// Counter-clockwise, starting at the lowest (then leftmost) vertex, collinear vertices removed.
Polygon Normalised(Polygon p);
Polygon Transformed(const Polygon& p, const Affine2& T);
bool Inside(const Polygon& poly, const Vec2& p);
/// Distance from p to the segment ab.
double SegmentDistance(const Vec2& p, const Vec2& a, const Vec2& b);

/// The outline of a union of axis-aligned rectangles (which may touch but not overlap), or
/// nothing when the union is not one simple polygon (split, holed, or touching at a corner).
std::optional<Polygon> UnionOutline(const std::vector<Rect>& rects);

}  // namespace msgraphs::sim::building
