// SPDX-License-Identifier: MIT
// Ray casting against one level of a world. Walls (split at doors, lintels above them) and
// boxes are yaw-oriented boxes, columns and round furniture vertical cylinders, floor and
// ceiling horizontal planes. A 2-D uniform grid over the level keeps a cast at a few cells:
// rays are walked cell by cell (Amanatides-Woo) and stop once the nearest hit is behind them.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "world.hpp"

namespace msgraphs::sim {

struct Hit {
  double range_m = 0.0;
  Eigen::Vector3d normal{0, 0, 1};  ///< unit, facing the ray
  Material material = Material::kPainted;
  /// The world wall (index into World::walls) whose long face was hit: face +1 is the face its
  /// normal() points out of (walls.csv face a), -1 the other (face b). wall = -1, face = 0 for
  /// anything else: floor, ceiling, furniture, door reveals and wall ends, the underside of
  /// lintels.
  std::int32_t wall = -1;
  std::int8_t face = 0;
  std::int32_t person = -1;  ///< a simulated person (index into Mission::people), else -1
};

class Scene {
 public:
  /// Builds the scene of `level` of `world`.
  Scene(const World& world, int level, double cell_size_m = 1.0);

  /// Per-thread scratch for Cast (so that a primitive spanning several cells is tested once).
  struct Scratch {
    std::vector<std::uint32_t> stamp;
    std::uint32_t ray = 0;
  };
  Scratch MakeScratch() const;

  /// Nearest surface along origin + t * direction (unit), 0 < t <= max_range.
  std::optional<Hit> Cast(const Eigen::Vector3d& origin,
                          const Eigen::Vector3d& direction,
                          double max_range,
                          Scratch& scratch) const;

  /// Distance from `p` to the nearest surface within `search_radius` (for residual tests);
  /// +infinity when none is that close.
  double DistanceToSurface(const Eigen::Vector3d& p, double search_radius = 1.0) const;

  /// Horizontal distance from `p` to the footprint of every primitive that overlaps the height
  /// band [z_lo, z_hi] (0 inside one); +infinity beyond `search_radius`. For path planning.
  double FootprintDistance(const Eigen::Vector2d& p,
                           double z_lo,
                           double z_hi,
                           double search_radius) const;

  double floor_z() const { return floor_z_; }
  std::size_t primitives() const { return boxes_.size() + cylinders_.size(); }

 private:
  struct BoxPrimitive {
    Eigen::Vector2d centre;
    double c, s;    // cos/sin of yaw
    double hx, hy;  // half extents along the box axes
    double z0, z1;
    Material material;
    std::int32_t wall = -1;  // index into World::walls for wall pieces, -1 for furniture
  };
  struct CylinderPrimitive {
    Eigen::Vector2d centre;
    double radius, z0, z1;
    Material material;
  };

  void Insert(std::uint32_t id, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi);
  bool TestPrimitive(std::uint32_t id,
                     const Eigen::Vector3d& o,
                     const Eigen::Vector3d& d,
                     Hit& best) const;
  // Calls visit(id) for every primitive listed in a grid cell within radius_m of p (a primitive
  // spanning several cells is visited once per cell; the callers take minima, so that is harmless).
  template <typename Visit>
  void ForEachPrimitiveNear(const Eigen::Vector2d& p, double radius_m, Visit&& visit) const {
    const auto cell_of = [&](double v, double o) {
      return static_cast<int>(std::floor((v - o) / cell_));
    };
    const int x0 = std::max(0, cell_of(p.x() - radius_m, origin_.x()));
    const int y0 = std::max(0, cell_of(p.y() - radius_m, origin_.y()));
    const int x1 = std::min(nx_ - 1, cell_of(p.x() + radius_m, origin_.x()));
    const int y1 = std::min(ny_ - 1, cell_of(p.y() + radius_m, origin_.y()));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const auto k = static_cast<std::size_t>(y * nx_ + x);
        for (std::uint32_t i = cell_start_[k]; i < cell_start_[k + 1]; ++i) visit(cells_[i]);
      }
    }
  }

  double floor_z_ = 0.0;
  std::optional<double> ceiling_z_;
  std::vector<BoxPrimitive> boxes_;
  std::vector<CylinderPrimitive> cylinders_;  // ids after the boxes
  // Grid: cells_[cell_start_[k] .. cell_start_[k+1]) lists the primitive ids of cell k.
  Eigen::Vector2d origin_;
  double cell_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<std::uint32_t> cell_start_;
  std::vector<std::uint32_t> cells_;
  std::vector<std::vector<std::uint32_t>> building_;  // only during construction
};

}  // namespace msgraphs::sim
