// SPDX-License-Identifier: MIT
// Every walkable room of every generated building in seeds 1..300 is reachable by the mission
// planner's robot (PlanMission refuses a building where one is not), and a 2-robot 120 s
// mission plans in every 10th of them, or, where 120 s is too short for two robots to share two
// rooms (the largest warehouses), a 300 s one. Slow (the planner's clearance grid): label
// integration.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

#include "building/generate.hpp"
#include "mission.hpp"
#include "scene.hpp"

namespace msgraphs::sim {
namespace {

TEST(BuildingMissions, EveryRoomIsReachableInSeeds1To300) {
  int failures = 0, too_short = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    building::BuildingFeatures f;
    const World w = building::GenerateBuilding(seed, {}, &f);
    const Scene scene(w, 0);
    MissionConfig config;
    const bool pair = seed % 10 == 0;
    config.robots = pair ? 2 : 1;
    config.duration_s = pair ? 120.0 : 1.0;
    config.shared_rooms = pair ? 2 : 0;
    config.seed = seed;
    std::string error;
    bool ok = PlanMission(w, scene, config, error).has_value();
    if (!ok && pair && error.find("share only") != std::string::npos) {
      ++too_short;
      config.duration_s = 300.0;
      ok = PlanMission(w, scene, config, error).has_value();
    }
    EXPECT_TRUE(ok) << "seed " << seed << " (" << building::ToString(f.style) << ", "
                    << building::ToString(f.clutter) << "): " << error;
    failures += ok ? 0 : 1;
  }
  std::printf(
      "300 buildings planned in %.1f s, %d refused; %d of 30 two-robot missions needed 300 s\n",
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), failures,
      too_short);
}

}  // namespace
}  // namespace msgraphs::sim
