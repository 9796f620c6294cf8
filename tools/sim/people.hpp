// SPDX-License-Identifier: MIT
// People walking through a mission: moving obstacles for the lidar. Each person is a vertical
// cylinder (about 0.25 m radius, 1.6-1.9 m tall, fabric) walking between random rooms at
// 0.8-1.4 m/s on paths from the mission planner's A*, pausing a few seconds at each
// destination. Their motion is in mission time, piecewise linear between knots (the truth file
// lists the knots). The static scene keeps its grid; the few people are tested per ray.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "nav_grid.hpp"
#include "scene.hpp"

namespace msgraphs::sim {

struct PeopleConfig {
  int count = 0;
  double radius_m = 0.25;
  double height_min_m = 1.6, height_max_m = 1.9;
  double speed_min_mps = 0.8, speed_max_mps = 1.4;
  double pause_min_s = 1.0, pause_max_s = 5.0;  ///< standing at each destination
  double clearance_m = 0.35;                    ///< kept from walls and furniture when planning
};

struct PersonKnot {
  double t_s = 0;  ///< mission time
  Eigen::Vector2d position{0, 0};
};

struct Person {
  int id = 0;
  double radius_m = 0.25, height_m = 1.75, speed_mps = 1.0;
  std::string start_room;
  std::vector<PersonKnot> knots;  ///< increasing times; straight walks or pauses between them

  /// Position and velocity at mission time t (held before the first and after the last knot).
  void StateAt(double t_s, Eigen::Vector2d& position, Eigen::Vector2d& velocity) const;
};

/// Plans `config.count` people over [0, duration_s] between the rooms `rooms` (indices into
/// World::rooms with their free cells). Deterministic in (seed, person). Allocates.
std::vector<Person> PlanPeople(const World& world,
                               const NavGrid& grid,
                               const std::vector<int>& rooms,
                               const std::vector<std::vector<Eigen::Vector2d>>& free_cells,
                               const PeopleConfig& config,
                               double duration_s,
                               std::uint64_t seed);

/// The people as lidar targets: positions are taken once per firing sequence and moved on
/// linearly to each laser's own firing time.
class PeopleScene {
 public:
  PeopleScene(const std::vector<Person>& people, double floor_z_m)
      : people_(&people), floor_z_m_(floor_z_m) {}
  std::size_t size() const { return people_->size(); }
  /// Fills position[i], velocity[i] of every person at mission time t (no allocation).
  void Snapshot(double t_s, Eigen::Vector2d* position, Eigen::Vector2d* velocity) const;
  /// Replaces `best` (and returns true) when a person is hit nearer than best.range_m along
  /// origin + s * direction; people are `dt_s` past their snapshot. A ray starting inside a
  /// person sees nothing of it.
  bool Cast(const Eigen::Vector2d* position,
            const Eigen::Vector2d* velocity,
            double dt_s,
            const Eigen::Vector3d& origin,
            const Eigen::Vector3d& direction,
            Hit& best) const;

 private:
  const std::vector<Person>* people_;
  double floor_z_m_;
};

}  // namespace msgraphs::sim
