// SPDX-License-Identifier: MIT
// The VLP-16 model: every one of the 16 lasers fires on the real schedule (2.304 us apart,
// 55.296 us per firing sequence, two sequences per 1,206-byte packet block) while the sensor
// turns at 600 RPM and the robot moves, so each ray leaves from where the lidar was at that
// microsecond. Ranges get Gaussian noise, random and grazing-angle dropouts, 2 mm quantisation
// and a 100 m limit; intensity follows the material and the incidence angle. Packets (and a
// position packet every 8 ms) go to a pcap with Ethernet/IPv4/UDP framing, as tcpdump would
// capture them on the robot.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>

#include "clocks.hpp"
#include "people.hpp"
#include "scene.hpp"
#include "trajectory.hpp"
#include "visibility.hpp"

namespace msgraphs::sim {

struct LidarSimConfig {
  Eigen::Isometry3d T_base_lidar = Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.30));
  double rpm = 600.0;
  double range_noise_sigma_m = 0.03;
  double max_range_m = 100.0;
  double dropout_probability = 0.003;
  double grazing_dropout_deg = 86.0;  ///< beyond this incidence angle nothing returns
  double position_packet_period_s = 0.008;
  bool nanosecond_pcap = false;
  int threads = 2;
};

struct LidarSimStats {
  std::uint64_t data_packets = 0;
  std::uint64_t position_packets = 0;
  std::uint64_t rays = 0;
  std::uint64_t returns = 0;
  std::uint64_t dropouts = 0;
  std::uint64_t person_returns = 0;  ///< returns from people
  std::uint64_t wall_returns = 0;    ///< returns from wall faces (counted in the visibility)
};

/// Renders the whole trajectory into `pcap_path`. `people` (optional) move in mission time
/// (trajectory.start_s() + t); `visibility` (optional) receives every wall-face return. Returns
/// false with `error` on I/O failure. The bytes do not depend on config.threads.
bool RenderLidar(const Scene& scene,
                 const Trajectory& trajectory,
                 const LidarSimConfig& config,
                 const RobotClocks& clocks,
                 std::uint64_t seed,
                 int robot,
                 const std::string& pcap_path,
                 LidarSimStats& stats,
                 std::string& error,
                 const PeopleScene* people = nullptr,
                 WallVisibility* visibility = nullptr);

}  // namespace msgraphs::sim
