// SPDX-License-Identifier: MIT
// Renders a planned mission into its output directory (docs/simulator.md, "Output"): per robot
// the VLP-16 pcap, the CAN candump log, the ground-truth TUM and start pose; for the mission
// mission.txt, the world, the map SVG and the truth files (walls, rooms, people, wall
// visibility, what each robot pair shares). Prints one summary per robot.
#pragma once

#include <cstdint>
#include <string>

#include "lidar_sim.hpp"
#include "mission.hpp"
#include "mission_report.hpp"
#include "odometry_sim.hpp"
#include "scene.hpp"
#include "world.hpp"

namespace msgraphs::sim {

struct OutputConfig {
  LidarSimConfig lidar;
  OdometrySimConfig odometry;
  double truth_rate_hz = 100.0;  ///< ground_truth.tum, 10 to 1000 Hz
  /// A wall bin counts as seen by a robot (for truth/shared.csv) with at least this many
  /// returns: a few scan lines' worth, so one stray ray through a door does not count.
  std::uint32_t shared_min_hits = 10;
  std::string world_path;  ///< copied to world.world
  std::string start_delays = "none";
};

bool WriteMissionOutputs(const World& world,
                         const Scene& scene,
                         const Mission& mission,
                         const OutputConfig& config,
                         const std::string& out_dir,
                         std::string& error);

}  // namespace msgraphs::sim
