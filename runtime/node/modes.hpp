// SPDX-License-Identifier: MIT
// msgraphs_node's modes: the node itself (--config), and two diagnostics.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "msgraphs/base/node_key.hpp"
#include "msgraphs/runtime/link/dds_settings.hpp"

namespace msgraphs::runtime {

std::string BuildLabel();
void PrintBanner(RobotId robot_id);

/// Runs the node from its configuration file (with "section.key=value" overrides); with
/// `check_only` validates the file and exits. Returns the exit code.
int RunNode(const std::string& config_path,
            const std::vector<std::string>& overrides,
            bool check_only);

/// Checks what this machine gives the node (clocks, real-time scheduling, memory locking) and
/// runs a real Fast DDS exchange between two participants on loopback. Returns the exit code.
int RunSelfCheck(std::uint32_t domain_id);

struct HeartbeatModeOptions {
  RobotId robot_id;
  link::DdsSettings dds;
  int expect_peers = 0;      ///< exit 0 once this many other robots were heard
  double duration_s = 10.0;  ///< give up (exit 3) after this long
  double rate_hz = 10.0;
};
/// Publishes telemetry only and reports the robots heard: a link check without sensors.
int RunHeartbeatMode(const HeartbeatModeOptions& options);

}  // namespace msgraphs::runtime
