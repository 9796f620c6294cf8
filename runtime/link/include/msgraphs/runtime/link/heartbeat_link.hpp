// SPDX-License-Identifier: MIT
// Publishes this robot's heartbeat and listens to every other robot's, over Fast DDS.
// Reliable, transient-local with history depth 1: a robot that joins late immediately learns
// the last heartbeat of every robot already running.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/node_key.hpp"
#include "msgraphs/base/time.hpp"
#include "msgraphs/runtime/link/dds_settings.hpp"

namespace msgraphs::runtime::link {

struct HeartbeatSample {
  RobotId robot_id;
  std::uint32_t sequence = 0;
  UnixTime stamp;
  Duration uptime;
  std::string build;
};

struct HeartbeatStats {
  std::uint64_t sent = 0;
  std::uint64_t received = 0;
  std::uint64_t rejected_version = 0;  ///< samples with an unknown version field
  std::uint64_t rejected_invalid = 0;  ///< robot id 0 or other impossible content
};

class HeartbeatLink {
 public:
  /// Creates the participant, topic, writer and reader. Errors: kInvalidConfig for bad
  /// settings, kIo when Fast DDS refuses an entity.
  /// `build_label` (version and commit, at most 64 characters) goes into every heartbeat.
  static Expected<std::unique_ptr<HeartbeatLink>> Create(RobotId self, const DdsSettings& settings,
                                                         const std::string& build_label);
  ~HeartbeatLink();
  HeartbeatLink(const HeartbeatLink&) = delete;
  HeartbeatLink& operator=(const HeartbeatLink&) = delete;

  /// Publishes one heartbeat stamped `stamp`. Never blocks longer than 100 ms.
  Status Publish(UnixTime stamp, Duration uptime);
  /// Waits up to `timeout` for the next heartbeat of another robot (own samples are skipped).
  /// kTimeout when none arrived.
  Expected<HeartbeatSample> Receive(Duration timeout);
  /// Number of remote readers currently matched with our writer.
  int matched_readers() const;
  const HeartbeatStats& stats() const;

 private:
  struct Impl;
  explicit HeartbeatLink(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace msgraphs::runtime::link
