// SPDX-License-Identifier: MIT
// A building seen from above for the merge-decision tests: rectangular spaces (rooms,
// corridors) separated by walls of a given thickness, with doors. A robot's observation is the
// set of spaces it saw whole; it yields what the robot would share: its distilled walls (every
// face of a seen space, facing into it, spanning its doors as a lintel would) and its free-space
// summary (the seen spaces free, their faces occupied, the doors of a seen space as openings: a
// robot in a room sees through its door), in the robot's own map frame.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <vector>

#include "msgraphs/core/collab/free_space_summary.hpp"
#include "msgraphs/core/graph/distilled_graph.hpp"

namespace msgraphs::test {

struct PlanSpace {
  double x0, y0, x1, y1;  ///< interior (free) extent, world frame
};
struct PlanDoor {
  Eigen::Vector2d a, b;  ///< on the wall's centre line, world frame
  int space_a, space_b;  ///< the spaces it joins
};

/// A space a robot saw, or the part of it between x0 and x1 (a corridor walked in part): the
/// cut ends are no walls, and beyond them the robot knows nothing.
struct Seen {
  int space = 0;
  double x0 = -1e9, x1 = 1e9;
};

struct PlanBuilding {
  std::vector<PlanSpace> spaces;
  std::vector<PlanDoor> doors;
  double wall_thickness_m = 0.15;

  /// A wall's faces seen from the given spaces, as distilled walls in the map frame
  /// (p_map = T_map_world p_world).
  core::DistilledGraph Walls(const std::vector<Seen>& seen, const Eigen::Isometry2d& T_map_world) const {
    core::DistilledGraph g;
    g.Init(4 * seen.size() + 8, 8);
    std::uint32_t id = 0;
    for (const Seen& v : seen) {
      const PlanSpace& r = spaces[static_cast<std::size_t>(v.space)];
      const double x0 = std::max(r.x0, v.x0), x1 = std::min(r.x1, v.x1);
      const Eigen::Vector2d c[4] = {{x0, r.y0}, {x1, r.y0}, {x1, r.y1}, {x0, r.y1}};
      for (int k = 0; k < 4; ++k) {
        if ((k == 1 && x1 < r.x1) || (k == 3 && x0 > r.x0)) continue;  // a cut end, not a wall
        // Counter-clockwise boundary: the interior is on the left, the face's normal points there.
        const Eigen::Vector2d a = c[k], b = c[(k + 1) % 4];
        const Eigen::Vector2d along = (b - a).normalized();
        const Eigen::Vector2d n_world(-along.y(), along.x());
        core::DistilledWall w;
        w.id = id++;
        const Eigen::Vector2d n = T_map_world.linear() * n_world;
        w.normal = Eigen::Vector3d(n.x(), n.y(), 0);
        const Eigen::Vector2d am = T_map_world * a, bm = T_map_world * b;
        w.d = -n.dot(am);
        w.a = am;
        w.b = bm;
        w.covariance = Eigen::Matrix3d::Identity() * 1e-4;
        static_cast<void>(g.walls.try_push_back(w));
      }
    }
    return g;
  }

  /// The summary of what a robot saw, in its map frame at `cell_m`.
  void Summary(const std::vector<Seen>& seen, const Eigen::Isometry2d& T_map_world, core::FreeSpaceSummary& out,
               double cell_m = 0.2) const {
    Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
    for (const Seen& v : seen) {
      const PlanSpace& r = spaces[static_cast<std::size_t>(v.space)];
      const double x0 = std::max(r.x0, v.x0), x1 = std::min(r.x1, v.x1);
      for (const Eigen::Vector2d& p : {Eigen::Vector2d(x0, r.y0), Eigen::Vector2d(x1, r.y0),
                                       Eigen::Vector2d(x0, r.y1), Eigen::Vector2d(x1, r.y1)}) {
        const Eigen::Vector2d m = T_map_world * p;
        lo = lo.cwiseMin(m);
        hi = hi.cwiseMax(m);
      }
    }
    lo.array() -= 1.0;
    hi.array() += 1.0;
    const int w = static_cast<int>((hi.x() - lo.x()) / cell_m) + 1, h = static_cast<int>((hi.y() - lo.y()) / cell_m) + 1;
    static_cast<void>(out.Reset(lo, static_cast<float>(cell_m), w, h));
    const Eigen::Isometry2d T_world_map = T_map_world.inverse();
    const double half = 0.5 * wall_thickness_m;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const Eigen::Vector2d centre = lo + Eigen::Vector2d((x + 0.5) * cell_m, (y + 0.5) * cell_m);
        const Eigen::Vector2d p = T_world_map * centre;
        core::SummaryCell state = core::SummaryCell::kUnknown;
        for (const Seen& v : seen) {
          const PlanSpace& r = spaces[static_cast<std::size_t>(v.space)];
          // Beyond the part seen; a whole end's wall band counts (its face was seen).
          const double band = half + 0.5 * cell_m;
          const double lo_x = v.x0 > r.x0 ? v.x0 : r.x0 - band, hi_x = v.x1 < r.x1 ? v.x1 : r.x1 + band;
          if (p.x() < lo_x || p.x() > hi_x) continue;
          // Inside by more than half a cell: free; within half a cell of a face (the wall
          // behind it): occupied.
          const double inside = std::min({p.x() - r.x0, r.x1 - p.x(), p.y() - r.y0, r.y1 - p.y()});
          if (inside > 0.5 * cell_m) {
            state = core::SummaryCell::kFree;
            break;
          }
          if (inside > -(half + 0.5 * cell_m)) state = core::SummaryCell::kOccupied;
        }
        out.set(static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x), state);
      }
    }
    // Every face seen leaves its cells occupied, as the returns on it would in a robot's grid
    // (cell centres alone miss a thin band that runs across a rotated grid).
    for (const Seen& v : seen) {
      const PlanSpace& r = spaces[static_cast<std::size_t>(v.space)];
      const double x0 = std::max(r.x0, v.x0), x1 = std::min(r.x1, v.x1);
      const Eigen::Vector2d c[4] = {{x0, r.y0}, {x1, r.y0}, {x1, r.y1}, {x0, r.y1}};
      for (int k = 0; k < 4; ++k) {
        if ((k == 1 && x1 < r.x1) || (k == 3 && x0 > r.x0)) continue;  // a cut end
        const Eigen::Vector2d a = T_map_world * c[k], b = T_map_world * c[(k + 1) % 4];
        const int steps = static_cast<int>((b - a).norm() / (0.25 * cell_m)) + 1;
        for (int i = 0; i <= steps; ++i) {
          const Eigen::Vector2d q = a + (b - a) * (static_cast<double>(i) / steps);
          const int cx = static_cast<int>((q.x() - lo.x()) / cell_m), cy = static_cast<int>((q.y() - lo.y()) / cell_m);
          if (cx < 0 || cy < 0 || cx >= w || cy >= h) continue;
          out.set(static_cast<std::size_t>(cy) * static_cast<std::size_t>(w) + static_cast<std::size_t>(cx),
                  core::SummaryCell::kOccupied);
        }
      }
    }
    for (const PlanDoor& d : doors) {
      bool a = false, b = false;
      for (const Seen& v : seen) {
        const bool within = d.b.x() >= v.x0 && d.a.x() <= v.x1;  // seen through, at least in part
        a = a || (v.space == d.space_a && within);
        b = b || (v.space == d.space_b && within);
      }
      if (a || b) static_cast<void>(out.add_opening({T_map_world * d.a, T_map_world * d.b}));
    }
    out.ComputeClearance();
  }
};

inline Eigen::Isometry2d Pose2(double x, double y, double yaw) {
  Eigen::Isometry2d T = Eigen::Isometry2d::Identity();
  T.linear() = Eigen::Rotation2Dd(yaw).toRotationMatrix();
  T.translation() << x, y;
  return T;
}

}  // namespace msgraphs::test
