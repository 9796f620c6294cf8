// SPDX-License-Identifier: MIT
// Building blocks in their own frame: double-loaded corridors of every shape (straight, L, T,
// U, loop) with strips of rooms along them, and the pieces styles put in the strips. A block
// frame has the main corridor along +x with its floor at 0 <= y <= corridor width.
#pragma once

#include <vector>

#include "plan.hpp"
#include "random.hpp"

namespace msgraphs::sim::building {

/// A strip of rooms along a corridor. `front` is the side facing the corridor (0: y0, 1: x1,
/// 2: y1, 3: x0); rooms are cut across the strip's axis (x for fronts 0 and 2, else y), and
/// each must face the corridor along [f0, f1] of that axis.
struct Strip {
  Rect rect;
  int front = 0;
  double f0 = 0, f1 = 0;
  bool core = false;  ///< inside a loop: may become one hall instead of rooms
  double a0() const { return front % 2 == 0 ? rect.x0 : rect.y0; }
  double a1() const { return front % 2 == 0 ? rect.x1 : rect.y1; }
  double depth() const { return front % 2 == 0 ? rect.height() : rect.width(); }
  /// The block rectangle of [along0, along1] x [depth0, depth1] (depth from the front).
  Rect Piece(double along0, double along1, double depth0, double depth1) const;
  /// The unit step along the strip's axis in the block frame.
  Vec2 AxisStep() const { return front % 2 == 0 ? Vec2(1, 0) : Vec2(0, 1); }
};

struct CorridorSpec {
  CorridorShape shape = CorridorShape::kStraight;
  double width_m = 2.0;
  double length_m = 40;     ///< main corridor (x)
  double arm_m = 20;        ///< the other corridors (y): L, T, U, loop
  double branch_at_m = 20;  ///< T: where the branch leaves the main corridor
  double depth_s_m = 6, depth_n_m = 6, depth_e_m = 6, depth_w_m = 6, depth_in_m = 5;
  bool split = false;  ///< corridor as several rooms with wide openings between them
};

struct CorridorLayout {
  std::vector<std::vector<Rect>> corridors;  ///< one entry per corridor room
  std::vector<std::pair<int, int>> joints;   ///< corridor rooms that get an opening
  std::vector<Strip> strips;
  int west_end = -1, east_end = -1;  ///< corridor rooms at x = 0 and x = length (straight)
  double y_lo = 0, y_hi = 0;         ///< the block's extent across (straight)
};

/// The corridors and strips of `spec`'s shape (CorridorShape::kNone: none).
CorridorLayout LayoutCorridors(const CorridorSpec& spec);

/// Cuts along a strip: [a, b] pieces from a0() to a1(), widths in [min_m, max_m] (1 cm grid),
/// each facing [f0, f1] by at least `frontage_m`.
std::vector<std::pair<double, double>> CutStrip(
    const Strip& s, Random& rng, double min_m, double max_m, double frontage_m = 1.9);
/// Cuts for a row of identical rooms `width_m` wide inside the frontage, with an end room on
/// each side taking the rest (at least `end_min_m`). `first`/`count`: the identical ones.
/// Empty when fewer than two fit.
std::vector<std::pair<double, double>> CutIdentical(
    const Strip& s, double width_m, double end_min_m, int& first, int& count);

/// Adds rooms and doors to a plan; geometry in a block frame mapped by `T` to the building.
class PlanBuilder {
 public:
  PlanBuilder(Plan& plan, const Affine2& T) : plan_(plan), T_(T) {}
  const Affine2& T() const { return T_; }
  int Room(RoomUse use, const Rect& r) { return Room(use, std::vector<Rect>{r}); }
  /// The union of `rects` as one room (when it is not one simple polygon, the plan is marked
  /// broken and the first rectangle stands in).
  int Room(RoomUse use, const std::vector<Rect>& rects);
  int RoomPolygon(RoomUse use, const Polygon& block_polygon);
  int Connect(int a, int b, const Connection& door);
  Plan& plan() { return plan_; }

 private:
  Plan& plan_;
  Affine2 T_;
};

/// Door presets (width, lintel, height, where along the wall).
enum class DoorKind : std::uint8_t { kSingle, kBed, kDouble, kWide, kOpening };
Connection DrawDoor(Random& rng, DoorKind kind, double no_lintel_chance = 0.0);

}  // namespace msgraphs::sim::building
