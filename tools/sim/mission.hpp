// SPDX-License-Identifier: MIT
// Missions: Spot-like robots walking through a level of the building, and people walking
// among them. Each robot starts in its own room (at its own start delay in mission time) and
// visits rooms; every visit has a kind (room_visits.hpp): a peek from the doorway, a partial
// walk near the entrance or a full exploration. Paths are planned on a clearance grid (A*,
// shortened by line of sight) and followed with Spot's limits (walker.hpp); the gait
// (gait.hpp) makes the base motion 6-DOF.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "gait.hpp"
#include "people.hpp"
#include "scene.hpp"
#include "trajectory.hpp"
#include "world.hpp"

namespace msgraphs::sim {

enum class VisitKind : std::uint8_t { kStart, kPeek, kPartial, kFull };
const char* ToString(VisitKind kind);

/// Relative weights of the kinds of the visits a robot makes after leaving its start room. The
/// shared rooms are always entered: their kinds are drawn from partial and full only (full when
/// both weigh 0). By default every visit is full (the shipped missions the demo and the tests
/// run); Benchmark() is the mix of the benchmark missions.
struct VisitKinds {
  double peek = 0.0, partial = 0.0, full = 1.0;
  static VisitKinds Benchmark() { return {0.3, 0.3, 0.4}; }
  /// Parses "peek=0.3,partial=0.3,full=0.4" (any subset; missing kinds weigh 0).
  static std::optional<VisitKinds> Parse(const std::string& text, std::string& error);
};

/// When each robot starts, in mission time (its recordings start then).
struct StartDelays {
  enum class Mode : std::uint8_t { kNone, kRandom, kExplicit } mode = Mode::kNone;
  double random_max_s = 60.0;        ///< random: uniform in [0, min(random_max_s, duration / 3)]
  std::map<int, double> explicit_s;  ///< explicit: robot id -> delay (others 0)
  /// Parses "none", "random" or "1=0,2=35.5,...".
  static std::optional<StartDelays> Parse(const std::string& text, std::string& error);
};

struct MissionConfig {
  int robots = 3;
  double duration_s = 300.0;
  std::uint64_t seed = 1;
  int level = 0;
  double max_speed_mps = 1.0;
  double max_turn_rate_rps = 0.8;
  double max_accel_mps2 = 0.5;
  double robot_radius_m = 0.35;  ///< clearance kept from walls and clutter
  double base_height_m = 0.5;    ///< Spot's body above the floor while walking (mean)
  int shared_rooms = 2;  ///< rooms every robot enters (partial or full): each pair shares them
  /// Shared rooms are entered with a partial visit (a point or two near the door), whatever the
  /// kinds' weights: a full visit of a 40 m corridor takes a minute, and a short mission must
  /// still reach every shared room. Off: their kinds are drawn like the others' (partial/full).
  bool shared_visit_partial = true;
  VisitKinds visit_kinds;
  StartDelays start_delays;
  GaitConfig gait;
  PeopleConfig people;
  // Visit shapes (documented configuration values).
  double peek_stand_min_m = 0.15;  ///< peek: base this far outside the room's boundary at least
  double peek_stand_max_m = 0.7;   ///< ... and at most
  double peek_look_min_s = 3.0, peek_look_max_s = 8.0;          ///< looking in, in total
  double peek_sweep_min_deg = 20.0, peek_sweep_max_deg = 45.0;  ///< left and right of straight in
  double partial_reach_m = 2.5;     ///< partial: points at most this far from the entrance
  double full_m2_per_point = 10.0;  ///< full: one point per this much floor, 3 to 6 points
  /// Spot stands this long at its start before walking off, so its odometry (integrated from
  /// the first sample) starts level: the stack takes the map frame as gravity-aligned. More
  /// than the gait's settle_s, or the trot would already rock the body at the first sample.
  double start_stand_s = 1.0;
};

struct Visit {
  std::string room;
  VisitKind kind = VisitKind::kFull;
  double start_s = 0;  ///< mission time: walking towards the room began
  double end_s = 0;    ///< mission time: the visit's last point reached (or looking in ended)
  int points = 0;      ///< points reached (peek: 1, the stand point; fewer if time ran out)
};

struct RobotPlan {
  int id = 0;
  double start_delay_s = 0;  ///< mission time of the robot's start (its trajectory's t = 0)
  PlanarPose start;
  std::string start_room;
  std::vector<std::string> rooms_visited;  ///< entered on purpose, in order, start room first
  std::vector<Visit> visits;               ///< every visit, start room first
  GaitParams gait;
  Trajectory trajectory;
};

struct Mission {
  MissionConfig config;
  std::vector<std::string> shared_rooms;
  std::vector<RobotPlan> robots;
  std::vector<Person> people;
};

std::optional<Mission> PlanMission(const World& world,
                                   const Scene& scene,
                                   const MissionConfig& config,
                                   std::string& error);

}  // namespace msgraphs::sim
