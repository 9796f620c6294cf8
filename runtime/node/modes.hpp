// SPDX-License-Identifier: MIT
// The node's modes until the full SLAM node exists (issue: onboard runtime).
#pragma once

#include <cstdint>
#include <string>

#include "msgraphs/base/node_key.hpp"
#include "msgraphs/runtime/link/dds_settings.hpp"

namespace msgraphs::runtime {

std::string BuildLabel();
void PrintBanner(RobotId robot_id);

/// Checks what this machine gives the node (clocks, real-time scheduling, memory locking) and
/// runs a real Fast DDS exchange between two participants on loopback. Returns the exit code.
int RunSelfCheck(std::uint32_t domain_id);

struct HeartbeatModeOptions {
  RobotId robot_id;
  link::DdsSettings dds;
  int expect_peers = 0;        ///< exit 0 once this many other robots were heard
  double duration_s = 10.0;    ///< give up (exit 3) after this long
  double rate_hz = 10.0;
};
/// Publishes heartbeats and reports the robots heard; the multi-process link test runs this.
int RunHeartbeatMode(const HeartbeatModeOptions& options);

}  // namespace msgraphs::runtime
