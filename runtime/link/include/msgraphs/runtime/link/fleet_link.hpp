// SPDX-License-Identifier: MIT
// The radio link of one robot: a single Fast DDS participant with five topics.
//
//   topic                         QoS (writer / reader)                         why
//   msgraphs/telemetry            reliable, transient-local, keep-last 1 per     liveness and
//   state; a
//                                 robot / keep-last 4 per robot                  late joiner sees
//                                 all
//   msgraphs/graph                reliable, transient-local, keep-last           distilled deltas;
//   a late
//                                 `graph_history` / keep-all up to reader_depth  joiner gets the
//                                 recent
//                                                                                ones, then a
//                                                                                resync
//   msgraphs/room_descriptor      reliable, transient-local, keep-last 1 per     newest descriptor
//   of
//                                 (robot, room) / keep-all                       every room for
//                                 late joiners
//   msgraphs/room_cloud_request   reliable, volatile, keep-last 16 / keep-all    only useful now
//   msgraphs/room_cloud           reliable, volatile, keep-last 8 / keep-all     large; only useful
//   now
//
// Every writer publishes asynchronously through one flow controller that caps the bytes per
// second the robot puts on the radio (`max_bytes_per_s`, 0: no cap), highest priority first:
// telemetry, requests, graph, descriptors, clouds. Data-sharing is off everywhere (it would
// bypass the network, and the fault tests with it). Readers keep every sample (keep-all) up
// to `reader_depth`: beyond it the reliable protocol holds the writer back instead of losing
// samples here.
//
// Incoming samples are checked before the node sees them: an unknown version field, a sender
// id of 0 or our own id, a payload larger than this robot accepts, or bytes that do not
// deserialise are refused and counted per topic (stats()); the node never sees them.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/fixed_vector.hpp"
#include "msgraphs/base/node_key.hpp"
#include "msgraphs/base/time.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/runtime/link/link_settings.hpp"

namespace msgraphs::runtime::link {

enum class NodeState : std::uint8_t { kStarting, kMapping, kInputDone, kStopping };
const char* ToString(NodeState state);

/// One robot's heartbeat and telemetry (Telemetry.idl).
struct Telemetry {
  RobotId robot;
  std::uint32_t counter = 0;
  UnixTime stamp;
  Duration uptime;
  std::string build;
  NodeState state = NodeState::kStarting;
  std::uint32_t keyframes = 0, walls = 0, rooms = 0;
  std::uint32_t graph_version = 0;
  std::uint64_t bytes_sent = 0, bytes_received = 0;
  FixedVector<std::uint16_t, 32> merged;
  FixedVector<std::uint16_t, 32> resync_from;
};

/// A collab message as it left the sender's CollabSession.
struct InboundMessage {
  core::CollabMessageType type = core::CollabMessageType::kDistilledGraph;
  std::uint16_t from = 0;
  std::uint16_t to = 0;  ///< 0: every robot
  std::vector<std::uint8_t> bytes;
};

struct TopicStats {
  std::uint64_t sent = 0, sent_bytes = 0;
  std::uint64_t write_failures = 0;  ///< refused by the writer (history full past its deadline)
  std::uint64_t received = 0, received_bytes = 0;
  std::uint64_t not_for_us = 0;         ///< addressed to another robot (requests, clouds)
  std::uint64_t rejected_version = 0;   ///< unknown version field
  std::uint64_t rejected_sender = 0;    ///< robot id 0, our own id, or fields that disagree
  std::uint64_t rejected_oversize = 0;  ///< payload above max_payload_bytes
  std::uint64_t undecodable = 0;        ///< bytes that did not deserialise (dropped by DDS)
  std::uint64_t lost = 0;               ///< DDS sample-lost reports (a writer overwrote them)
};

struct LinkStats {
  /// [0..4] by core::CollabMessageType, [5] telemetry.
  std::array<TopicStats, core::kCollabMessageTypes + 1> topics{};
  std::uint64_t robots_appeared = 0, robots_vanished = 0;
};

/// Makes participants of this process talk through the network stack as separate processes do
/// (Fast DDS otherwise short-cuts them in memory): for the self-check's latency figures. Call
/// before the first Create.
void DisableIntraprocessDelivery();

class FleetLink final : public core::CollabOutbox {
 public:
  /// Creates the participant and every topic, writer and reader. kInvalidConfig for bad
  /// settings or robot id 0, kIo when Fast DDS refuses an entity.
  static Expected<std::unique_ptr<FleetLink>> Create(RobotId self, const LinkSettings& settings);
  ~FleetLink() override;
  FleetLink(const FleetLink&) = delete;
  FleetLink& operator=(const FleetLink&) = delete;

  /// core::CollabOutbox: writes one message (thread-safe). A refused write is counted.
  void Send(core::CollabMessageType type,
            std::uint16_t to,
            std::span<const std::uint8_t> bytes) override;

  /// Waits up to `timeout` for the next collab message for this robot; true when `out` holds
  /// one. `out.bytes` is reused (it stops growing at the largest message); Fast DDS's own
  /// reception allocates as Fast DDS does, which no test here counts.
  bool Receive(InboundMessage& out, Duration timeout);

  /// Publishes our telemetry (robot and stamp are filled in).
  Status PublishTelemetry(Telemetry telemetry);
  /// The latest telemetry of every other robot heard, and when it arrived (steady clock).
  struct PeerView {
    Telemetry telemetry;
    SteadyTime heard;  ///< when its latest telemetry arrived
    bool has_telemetry = false;
    bool alive = false;  ///< its participant is currently discovered
  };
  std::vector<PeerView> Peers() const;

  /// Remote readers matched with our telemetry writer (robots that can hear us).
  int matched_readers() const;
  LinkStats stats() const;

 private:
  friend class RosPublisher;  // shares the participant
  void* participant() const;
  struct Impl;
  explicit FleetLink(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace msgraphs::runtime::link
