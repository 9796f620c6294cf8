// SPDX-License-Identifier: MIT
// The clocks of one simulated robot. Every device sees the mission's timeline through its own
// clock, as on a real robot. The functions take the robot's own time t (seconds since the
// robot started, which is start_delay_s into the mission):
//   host (UNIX, what pcap and candump stamp): unix_offset_s + start_delay_s + t, i.e.
//     unix_offset_s is the robot's clock at mission time 0; every robot has its own offset,
//     so robots' clocks are not synchronised (spec section 5);
//   lidar (microseconds past the hour, free-running indoors without GPS): its own phase and drift;
//   CAN bridge (microseconds, wraps at 2^32): its own start.
#pragma once

#include <cmath>
#include <cstdint>

#include "msgraphs/base/time.hpp"
#include "random.hpp"

namespace msgraphs::sim {

struct RobotClocks {
  double unix_offset_s = 1.7e9;
  double lidar_phase_us = 0.0;  ///< lidar clock at t = 0, past the hour
  double lidar_drift_ppm = 0.0;
  double bridge_start_us = 0.0;  ///< bridge clock at t = 0
  double start_delay_s = 0.0;    ///< mission time at which the robot starts (its t = 0)

  static RobotClocks Draw(std::uint64_t seed, int robot) {
    Random r = Random::Stream(seed, 0x636C6F63, static_cast<std::uint64_t>(robot));  // "cloc"
    RobotClocks c;
    // Within a day of a fixed date, whole microseconds, different per robot.
    c.unix_offset_s = 1'763'800'000.0 + std::floor(r.Uniform(0, 86400.0) * 1e6) / 1e6;
    c.lidar_phase_us = std::floor(r.Uniform(0, 3.6e9));
    c.lidar_drift_ppm = r.Uniform(-30, 30);
    c.bridge_start_us = std::floor(r.Uniform(0, 4.29e9));
    return c;
  }

  UnixTime Host(double t) const {
    return UnixTime::FromNanoseconds(static_cast<std::int64_t>(std::llround(unix_offset_s * 1e6)) *
                                         1000 +
                                     static_cast<std::int64_t>(std::llround(start_delay_s * 1e9)) +
                                     static_cast<std::int64_t>(std::llround(t * 1e9)));
  }
  std::uint32_t LidarTimeOfHourUs(double t) const {
    const double us = lidar_phase_us + t * 1e6 * (1.0 + lidar_drift_ppm * 1e-6);
    return static_cast<std::uint32_t>(std::fmod(std::floor(us), 3.6e9));
  }
  std::uint32_t BridgeUs(double t) const {
    return static_cast<std::uint32_t>(
        static_cast<std::uint64_t>(std::llround(bridge_start_us + t * 1e6)) & 0xFFFFFFFFu);
  }
};

}  // namespace msgraphs::sim
