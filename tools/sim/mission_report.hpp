// SPDX-License-Identifier: MIT
// mission.txt: what the simulation drew, for the evaluation (docs/simulator.md, "Output").
// Line-oriented, "key value" pairs after a leading word; robots' lines end with their rooms:
//   robot <id> start_room R start_delay_s S unix_offset_s U ... rooms R1 R2 ...
//   visit robot <id> room R kind peek|partial|full|start start_s T0 end_s T1 points N
//   slip robot <id> start_s T duration_s D kind scale|yaw|scale+yaw scale F yaw_deg Y true_m M
//   person <id> start_room R radius_m .. height_m .. speed_mps .. knots N
// Times are mission time (seconds from the mission start; a robot's own clock reads
// unix_offset_s + mission time). Also truth/people.csv: every person's knots.
#pragma once

#include <string>
#include <vector>

#include "clocks.hpp"
#include "lidar_sim.hpp"
#include "mission.hpp"
#include "odometry_sim.hpp"
#include "world.hpp"

namespace msgraphs::sim {

struct RobotReport {
  const RobotPlan* plan = nullptr;
  RobotClocks clocks;
  OdometrySimStats odometry;
  LidarSimStats lidar;
};

struct MissionSettings {  ///< how the recordings were made (not part of MissionConfig)
  double truth_rate_hz = 100.0;
  bool slip = true;
  std::string start_delays = "none";  ///< as given on the command line
};

bool WriteMissionTxt(const World& world,
                     const Mission& mission,
                     const MissionSettings& settings,
                     const std::vector<RobotReport>& robots,
                     const std::string& path);
bool WritePeopleCsv(const Mission& mission, const std::string& path);

}  // namespace msgraphs::sim
