// SPDX-License-Identifier: MIT
// One robot's onboard pipeline (msgraphs_node runs exactly this):
//
//   LiDAR thread     Velodyne UDP or pcap -> assembled scans --[scan queue]--------+
//   odometry thread  SocketCAN or candump -> encoder poses  --[odometry queue]-----+
//                                                                                  v
//   SLAM thread      LocalMapper (local S-Graph); every exchange period: CollabPublisher::Prepare
//                    (distillation, room descriptors, free space, place clouds) into an exchange
//                    for the collab thread, and the latest wall priors from the other robots
//   collab thread    FleetLink -> CollabSession::Receive / Ingest (the exchange, sent through the
//                    link) / Match (room matching, fine alignment, merge decision, collaborative
//                    graph); resync requests; wall priors for the SLAM thread
//   supervisor       (the caller's thread, Run): telemetry, status lines, the status LED,
//                    exit conditions, the output files at the end
//
// The SLAM thread never takes the session's mutex: it meets the collab thread only in small
// mailboxes (the exchange, place requests, wall priors, the fleet's walls for the ROS view),
// each held for a copy or a pointer swap, never across Match. When the collab thread has not
// taken the last exchange yet, the SLAM thread does not wait: it tries again after its next
// scan (counted). Queue capacities are in the configuration; a full queue drops the newest
// element and counts it (live inputs) or holds the reader back (lock-step replay).
#pragma once

#include <atomic>
#include <memory>
#include <string>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/runtime/config/node_config.hpp"

namespace msgraphs::runtime {

class Node {
 public:
  /// Allocates every buffer, opens the inputs, the LED and the DDS link. A failure carries a
  /// message for the operator in `error`.
  static std::unique_ptr<Node> Create(const config::NodeConfig& config,
                                      const std::string& build_label,
                                      std::string& error);
  ~Node();
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  /// Runs until `stop` becomes true, an input fails, or the configured exit condition holds.
  /// Prints status lines; writes the output files. Returns the process exit code (0 clean,
  /// 1 an input or the link failed).
  int Run(const std::atomic<bool>& stop);

 private:
  struct Impl;
  explicit Node(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace msgraphs::runtime
