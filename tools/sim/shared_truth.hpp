// SPDX-License-Identifier: MIT
// Ground truth for "who could possibly merge with whom": per robot pair, the rooms both robots
// were inside (from the true trajectories and the room polygons), the rooms one only looked
// into while the other entered, and the wall faces both lidars saw (WallVisibility bins hit at
// least min_hits times by each), with how well that shared structure constrains the two
// horizontal directions: the eigenvalues of M = sum(len * n n^T) over the shared bins (n the
// face normal, len the bin's solid length). eig_min_m near 0 means all shared walls are
// parallel: a merge along them is unconstrained.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "trajectory.hpp"
#include "visibility.hpp"
#include "world.hpp"

namespace msgraphs::sim {

struct RobotTruth {
  int id = 0;
  const Trajectory* trajectory = nullptr;
  const WallVisibility* visibility = nullptr;
  std::vector<std::string> peeked;  ///< rooms the robot had a peek visit to
};

struct PairSharing {
  int robot_a = 0, robot_b = 0;
  std::vector<std::string> rooms_both_inside;
  std::vector<std::string> peeked_by_a_entered_by_b, peeked_by_b_entered_by_a;
  double shared_wall_m = 0;  ///< solid face length both saw
  int shared_faces = 0;      ///< wall faces with at least one shared bin
  double eig_min_m = 0, eig_max_m = 0;
  double major_normal_deg = 0;  ///< direction of the best-constrained normal, [0, 180)
};

/// Rooms (ids, in world order) whose polygon held the robot's base at some time (10 Hz).
std::vector<std::string> RoomsInside(const World& world, int level, const Trajectory& trajectory);

std::vector<PairSharing> ComputeSharing(const World& world,
                                        int level,
                                        const std::vector<RobotTruth>& robots,
                                        std::uint32_t min_hits);

/// robot,wall,face,bin,from_m,to_m,solid_m,hits for every bin a robot hit.
bool WriteVisibilityCsv(const std::vector<RobotTruth>& robots, const std::string& path);
bool WriteSharedCsv(const std::vector<PairSharing>& pairs,
                    std::uint32_t min_hits,
                    const std::string& path);

}  // namespace msgraphs::sim
