// SPDX-License-Identifier: MIT
// The lock-step mission clock of msgraphs_collab: every robot's scans in order of mission time
// (the robot's scan stamps from its first scan, plus its start delay), an exchange at the first
// scan at or after every multiple of `every_s`, and a last one after every mapper finished.
// Deterministic: the result depends on the recordings and options only.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "mission.hpp"
#include "radio.hpp"

namespace msgraphs::tools::collab {

struct ExchangeRecord {
  double mission_time_s = 0;
  std::array<std::uint64_t, kMessageTypes> bytes{};  ///< cumulative, all links
};

struct MissionRun {
  std::vector<ExchangeRecord> exchanges;  ///< the final exchange included
  double mission_time_s = 0;              ///< the last scan's mission time
  double run_time_s = 0;                  ///< wall time of the whole run
};

/// Runs the mission; `after_exchange(mission_time_s)` is called after every exchange.
/// `until_s` > 0 ends it at the first scan at or after that mission time.
MissionRun RunLockStep(Mission& mission,
                       double every_s,
                       double until_s,
                       const std::function<void(double)>& after_exchange);

}  // namespace msgraphs::tools::collab
