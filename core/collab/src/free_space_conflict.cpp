// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/free_space_conflict.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace msgraphs::core {
namespace {

bool NearWall(const WallIndex& walls, const Eigen::Vector2d& p, double distance_m) {
  for (const AlignWall& w : walls.walls()) {
    if (std::fabs(w.n.dot(p) + w.d) > distance_m) continue;
    const Eigen::Vector2d u(-w.n.y(), w.n.x());
    const double s = u.dot(p), s0 = std::min(u.dot(w.a), u.dot(w.b)), s1 = std::max(u.dot(w.a), u.dot(w.b));
    if (s >= s0 - distance_m && s <= s1 + distance_m) return true;
  }
  return false;
}

// The sample at `p` of a wall running from `a` to `b` (y's frame) lies in a doorway of y's: y
// mapped the same line on both sides of it, each piece overlapping the wall, the gap between
// them no wider than a doorway. The wall is then the doorway's lintel, seen by one robot (a
// VLP-16 sees a 4 m lintel only from 12 m away) and not the other. A wall that merely ends in
// line with y's walls (a corridor's end wall between partitions aligned across the corridor)
// does not span both pieces, and stays a conflict.
bool InDoorwayOf(const WallIndex& walls, const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p,
                 const Eigen::Vector2d& n, const FreeSpaceConflictConfig& c) {
  const Eigen::Vector2d u = (b - a).normalized();
  const double sa = std::min(u.dot(a), u.dot(b)), sb = std::max(u.dot(a), u.dot(b)), sp = u.dot(p);
  double left_end = -1e300, right_start = 1e300;  // the nearest y pieces ending before p, starting after
  for (const Eigen::Vector2d& m : {n, Eigen::Vector2d(-n)}) {
    walls.ForEachNear(m, -m.dot(p), 0.17, c.door_wall_distance_m, [&](const AlignWall& w) {
      const double s0 = std::min(u.dot(w.a), u.dot(w.b)), s1 = std::max(u.dot(w.a), u.dot(w.b));
      const double overlap = std::min(s1, sb) - std::max(s0, sa);
      if (overlap < c.extent_tolerance_m) return;
      if (s1 <= sp) left_end = std::max(left_end, s1);
      if (s0 >= sp) right_start = std::min(right_start, s0);
    });
  }
  return right_start - left_end <= c.max_opening_m;
}

// y saw an opening of its own on the same line within `reach_m` of the segment a-b: the two
// robots saw one door, its extent differently (from another side, obliquely, in part).
bool SameDoorway(const FreeSpaceSummary& y, const Eigen::Vector2d& a, const Eigen::Vector2d& b, double line_m,
                 double reach_m) {
  const double length = (b - a).norm();
  if (length <= 0) return false;
  const Eigen::Vector2d u = (b - a) / length, n(-u.y(), u.x());
  for (const Opening& o : y.openings()) {
    if (std::fabs(n.dot(o.a - a)) > line_m || std::fabs(n.dot(o.b - a)) > line_m) continue;
    const double s0 = std::min(u.dot(o.a - a), u.dot(o.b - a)), s1 = std::max(u.dot(o.a - a), u.dot(o.b - a));
    if (s1 >= -reach_m && s0 <= length + reach_m) return true;
  }
  return false;
}

// Robot x saw its own wall near `p_x` (x's frame): a cell of x's summary within `reach_m` of the
// sample, along the wall and across it, is occupied. A distilled wall's extent is the union of
// what was associated to its plane, so it spans every doorway between two sightings of the
// wall, doorways x never saw into; there x claims no wall, and another robot that walked
// through the door must not be refuted by it. Along the wall too, so that a gap of a cell or
// two in what a grazing view left occupied still counts as wall: only a doorway's middle, more
// than `reach_m` from both jambs, is unseen. An empty summary (none yet) says nothing either way.
bool SeenSolid(const FreeSpaceSummary& x, const Eigen::Vector2d& p_x, const Eigen::Vector2d& n_x, double reach_m,
               double step_m) {
  if (x.empty()) return true;
  const Eigen::Vector2d u_x(-n_x.y(), n_x.x());
  for (double along = -reach_m; along <= reach_m + 1e-9; along += step_m) {
    for (double across = -reach_m; across <= reach_m + 1e-9; across += step_m) {
      if (x.state_at(p_x + along * u_x + across * n_x) == SummaryCell::kOccupied) return true;
    }
  }
  return false;
}

// The stretches counted so far for one pair of maps, y's frame: one face of one wall counts
// once. A robot's map may hold a wall's face twice (two landmarks of one plane that never
// merged, the same extent), and one doorway then counted two or three times over (benchmark
// m037: three copies of one 1.1 m stretch). The other face of a thin wall is another
// observation, as it is in the agreement, and counts.
class CountedStretches {
 public:
  /// The part of a-b (y's frame; `n` its wall's facing) not yet counted, in metres, and records it.
  double Add(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& n, double line_m) {
    const double length = (b - a).norm();
    if (length <= 0) return 0;
    const Eigen::Vector2d u = (b - a) / length, across(-u.y(), u.x());
    double covered = 0;
    for (std::size_t i = 0; i < count_; ++i) {
      const Stretch& s = stretches_[i];
      if (s.n.dot(n) < kSameFacing) continue;
      if (std::fabs(across.dot(s.a - a)) > line_m || std::fabs(across.dot(s.b - a)) > line_m) continue;
      const double s0 = std::min(u.dot(s.a - a), u.dot(s.b - a)), s1 = std::max(u.dot(s.a - a), u.dot(s.b - a));
      covered += std::max(0.0, std::min(s1, length) - std::max(s0, 0.0));
    }
    if (count_ < stretches_.size()) stretches_[count_++] = {a, b, n};
    return std::max(0.0, length - covered);
  }

 private:
  static constexpr double kSameFacing = 0.985;  // cos 10 degrees
  struct Stretch {
    Eigen::Vector2d a, b, n;
  };
  std::array<Stretch, 256> stretches_{};
  std::size_t count_ = 0;
};

}  // namespace

Status FreeSpaceConflictConfig::Validate() const {
  if (!(clearance_m > 0) || !(sample_step_m > 0.01 && sample_step_m <= 1.0) || !(opening_margin_m >= 0) ||
      !(extent_tolerance_m >= 0) || !(max_opening_m >= 0) ||
      !(door_solid_share > 0 && door_solid_share <= 1) || !(min_stretch_m >= 0) || !(door_wall_distance_m > 0) ||
      !(min_door_m >= 0)) {
    return Error{Errc::kInvalidConfig, "free-space conflict: distances and shares must be positive"};
  }
  return Ok();
}

FreeSpaceConflict ConflictOf(const WallIndex& walls_x, const FreeSpaceSummary& summary_x,
                             const PlanarTransform& T_y_x, const WallIndex& walls_y,
                             const FreeSpaceSummary& summary_y, const FreeSpaceConflictConfig& c,
                             ConflictVisitor* visitor, bool between_robots) {
  FreeSpaceConflict out;
  if (summary_y.empty()) return out;
  const double step = c.sample_step_m;
  CountedStretches counted;
  for (const AlignWall& w : walls_x.walls()) {
    const double inner = w.length_m - 2 * c.extent_tolerance_m;
    if (inner <= 0) continue;
    const Eigen::Vector2d dir = (w.b - w.a) / w.length_m;
    const Eigen::Vector2d a = T_y_x * (w.a + c.extent_tolerance_m * dir);
    const Eigen::Vector2d b = T_y_x * (w.b - c.extent_tolerance_m * dir);
    const Eigen::Vector2d n_y = T_y_x.R() * w.n;
    const auto n = static_cast<int>(std::ceil(inner / step));
    // Contiguous stretches in seen-through space of at least min_stretch_m count: a wrong
    // transform lays walls across free space, the maps' own noise leaves a short stretch here
    // and there (an extent grown past a door, a furniture face one robot mapped as a wall).
    int run = 0;
    const auto min_run = static_cast<int>(std::ceil(c.min_stretch_m / (inner / n)));
    auto close_run = [&](int end) {
      if (run >= min_run) {
        const Eigen::Vector2d from = a + (b - a) * (static_cast<double>(end - run) / n);
        const Eigen::Vector2d to = a + (b - a) * (static_cast<double>(end) / n);
        // Two landmarks of one face lie within the plane association's gate (a few cm).
        const double fresh = between_robots ? counted.Add(from, to, n_y, 0.5 * c.sample_step_m)
                                            : inner * run / n;
        if (fresh > 0) {
          out.walls_in_free_m += fresh;
          if (visitor != nullptr) visitor->Counted(ConflictKind::kWallInFree, from, to, fresh);
        }
      }
      run = 0;
    };
    const Eigen::Vector2d a_x = w.a + c.extent_tolerance_m * dir;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d p = a + (b - a) * ((i + 0.5) / n);
      const Eigen::Vector2d p_x = a_x + dir * (inner * (i + 0.5) / n);
      const bool in_free = static_cast<double>(summary_y.clearance_m(p)) >= c.clearance_m &&
                           !summary_y.NearOpening(p, c.opening_margin_m) && !InDoorwayOf(walls_y, a, b, p, n_y, c) &&
                           (!between_robots || SeenSolid(summary_x, p_x, w.n, c.door_wall_distance_m,
                                                    0.5 * static_cast<double>(summary_x.cell_m())));
      if (in_free)
        ++run;
      else
        close_run(i);
    }
    close_run(n);
  }
  for (const Opening& o : summary_x.openings()) {
    const Eigen::Vector2d a = T_y_x * o.a, b = T_y_x * o.b;
    const double width = (b - a).norm();
    if (width < c.min_door_m) continue;  // narrower than any door: a gap between returns
    const auto n = std::max(1, static_cast<int>(std::ceil(width / step)));
    double solid = 0;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d p = a + (b - a) * ((i + 0.5) / n);
      if (summary_y.state_at(p) != SummaryCell::kOccupied) continue;
      if (summary_y.NearOpening(p, c.opening_margin_m)) continue;
      if (!NearWall(walls_y, p, c.door_wall_distance_m)) continue;
      solid += width / n;
    }
    if (solid >= c.door_solid_share * width && !SameDoorway(summary_y, a, b, c.door_wall_distance_m, c.max_opening_m)) {
      out.openings_on_solid_m += solid;
      if (visitor != nullptr) visitor->Counted(ConflictKind::kOpeningOnSolid, a, b, solid);
    }
  }
  return out;
}

}  // namespace msgraphs::core
