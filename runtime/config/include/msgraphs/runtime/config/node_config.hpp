// SPDX-License-Identifier: MIT
// Everything one msgraphs_node needs, read from its configuration file (docs/runtime.md has
// every key with its default and range; runtime/node/example.conf is a complete file).
// Relative paths are relative to the file's folder. Validation names the file and line of
// the offending entry, and unknown sections or keys are errors.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "msgraphs/base/node_key.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/runtime/link/link_settings.hpp"

namespace msgraphs::runtime::config {

enum class LidarSource : std::uint8_t { kUdp, kPcap };
/// kUdp: CAN frames as candump lines, one per UDP datagram (a CAN-to-Ethernet gateway, or
/// msgraphs_replay --candump), stamped by their arrival like live SocketCAN frames.
enum class OdometrySource : std::uint8_t { kSocketCan, kCandump, kUdp };
/// Recorded inputs: kLockstep as fast as the SLAM thread takes them (nothing is dropped, the
/// readers wait); kRecorded at the recorded pace times `speed` (queues overflow as they would
/// live, and count it).
enum class Pace : std::uint8_t { kLockstep, kRecorded };

struct NodeConfig {
  std::string file;  ///< where it was read from

  // [robot]
  RobotId robot;
  std::string name;

  // [lidar]
  LidarSource lidar_source = LidarSource::kUdp;
  std::string pcap_path;
  std::string bind_address = "0.0.0.0";
  std::uint16_t data_port = 2368, position_port = 8308;
  std::string sensor_address;  ///< empty: accept any sender

  // [odometry]
  OdometrySource odometry_source = OdometrySource::kSocketCan;
  std::string candump_path;
  std::string can_interface = "can0";
  std::uint16_t can_udp_port = 20000;  ///< kUdp

  // [replay]
  Pace pace = Pace::kRecorded;
  double speed = 1.0;

  // [mapping]: T_base_lidar, base height, keyframe spacing, ranges (LocalMapperConfig).
  core::LocalMapperConfig mapper;

  // [collab]
  core::CollabSessionConfig collab;
  double exchange_period_s = 10.0;  ///< sensor time between two Publish calls
  /// Wall time between two CollabSession::Match calls, and before an unanswered room cloud
  /// request is sent again (a capped radio may take seconds to deliver a cloud).
  double match_period_s = 0.5;
  double request_retry_s = 10.0;
  bool feedback = true;  ///< other robots' walls into the local S-Graph
  /// The walls' marginal covariances computed on the marginals thread, the exchange sent once
  /// they are done (true), or computed in the exchange on the SLAM thread (false: a
  /// factorisation of the whole graph there, about a second at 4,000 keyframes).
  /// docs/multi-robot.md, "Wall covariance".
  bool marginals_in_background = true;

  // [link]
  link::LinkSettings link;
  double telemetry_hz = 2.0;

  // [runtime]
  int realtime_priority = 0;  ///< SCHED_FIFO priority of the sensor threads; 0: normal
  bool lock_memory = false;
  double status_period_s = 5.0;
  std::size_t scan_queue = 8;         ///< assembled scans waiting for SLAM
  std::size_t odometry_queue = 4096;  ///< odometry samples waiting for SLAM
  /// After the inputs end (recordings) and every peer heard has ended too, keep exchanging
  /// this long, then exit; 0: run until a signal.
  double exit_after_done_s = 0.0;
  double max_run_s = 0.0;  ///< stop after this long whatever happens; 0: no limit

  // [led]
  std::string led_chip;  ///< e.g. "gpiochip0"; empty: no status LED
  std::string led_line;  ///< line name or offset on the chip
  bool led_active_low = false;

  // [ros]: the map on ROS 2 topics for RViz2 (runtime/link ros_publisher.hpp)
  bool ros_enabled = true;
  double ros_cloud_period_s = 10.0;  ///< the map cloud at most this often (only while subscribed)

  // [checkpoint]
  std::string checkpoint_dir;      ///< empty: no checkpoint; else the journal lives here
  double checkpoint_sync_s = 5.0;  ///< fsync period (power-cut safety)
  /// A snapshot (and a new journal) every this many keyframes: the journal is compacted, and a
  /// restart loads the snapshot and replays the keyframes since (docs/runtime.md). 0: the
  /// journal only, replayed whole at a restart.
  std::size_t snapshot_every_keyframes = 50;
  /// CRC-32 of what shapes the map that the config file sets ([mapping], [rooms], the odometry
  /// noise, T_base_lidar): a snapshot made under other values is not loaded (derived, not read).
  std::uint32_t mapper_settings_crc = 0;
  /// The robot's top speed: after a restart, how far it can have walked while the node was
  /// down (the relocalisation's reach). Spot's is 1.6 m/s.
  double relocalise_max_speed_mps = 1.6;

  // [output]
  std::string output_dir;  ///< empty: no files at exit
};

/// The CRC-32 of the mapper settings a config file can set (NodeConfig::mapper_settings_crc).
std::uint32_t MapperSettingsCrc(const core::LocalMapperConfig& mapper);

/// Reads and validates. On failure returns false with a message naming file and line.
/// `overrides` are "section.key=value" strings applied over the file (command line --set).
bool LoadNodeConfig(const std::string& path,
                    const std::vector<std::string>& overrides,
                    NodeConfig& out,
                    std::string& error);
/// The same from text (tests); `name` stands for the file in messages, `base_dir` resolves
/// relative paths.
bool ParseNodeConfig(const std::string& text,
                     const std::string& name,
                     const std::string& base_dir,
                     const std::vector<std::string>& overrides,
                     NodeConfig& out,
                     std::string& error);

}  // namespace msgraphs::runtime::config
