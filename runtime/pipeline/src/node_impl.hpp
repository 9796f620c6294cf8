// SPDX-License-Identifier: MIT
// Node internals shared by its thread loops (one file per thread).
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/drivers/gpio/gpio.hpp"
#include "msgraphs/drivers/gpio/status_led.hpp"
#include "msgraphs/runtime/link/fleet_link.hpp"
#include "msgraphs/runtime/link/ros_publisher.hpp"
#include "msgraphs/runtime/pipeline/bounded_queue.hpp"
#include "msgraphs/runtime/pipeline/journal.hpp"
#include "msgraphs/runtime/pipeline/latency_window.hpp"
#include "msgraphs/runtime/pipeline/node.hpp"
#include "msgraphs/runtime/pipeline/replay_clock.hpp"

namespace msgraphs::runtime {

/// One assembled sweep, in the lidar frame, as the SLAM thread needs it.
struct ScanSlot {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> time_offset_s;
  double start_s = 0, end_s = 0;
  std::uint64_t sequence = 0;
  SteadyTime last_packet;  ///< when its last packet arrived (or was due, in replay)
};

struct OdometrySlot {
  double stamp_s = 0;
  Eigen::Isometry3d T_odom_base = Eigen::Isometry3d::Identity();
};

/// Counters a thread updates and the supervisor reads; relaxed atomics (statistics only).
struct InputCounters {
  std::atomic<std::uint64_t> items{0};     ///< scans or odometry samples delivered
  std::atomic<std::uint64_t> rejected{0};  ///< malformed packets or frames
  /// LiDAR points left out of a sweep: beyond its slot's reserved capacity, or dropped by a
  /// full assembler (CopySweep). Never silently: the status line shows them.
  std::atomic<std::uint64_t> points_cut{0};
  std::atomic<bool> done{false};           ///< the recording ended (never for live inputs)
  std::atomic<bool> failed{false};
  std::mutex error_mutex;
  std::string error;
  void Fail(const std::string& why) {
    {
      std::lock_guard<std::mutex> lock(error_mutex);
      error = why;
    }
    failed = true;
  }
};

/// What the SLAM thread reports after each scan (under `mutex`).
struct SlamStatus {
  std::uint64_t scans = 0, keyframes = 0, no_odometry = 0;
  std::uint32_t walls = 0, rooms = 0;
  std::uint32_t graph_version = 0;  ///< the distilled version we have sent
  double keyframe_p50_ms = 0, keyframe_p99_ms = 0;
  double wire_p50_ms = 0, wire_p99_ms = 0, wire_max_ms = 0;  ///< last packet -> on the wire
  std::uint64_t wire_samples = 0;
  std::uint64_t publishes = 0;
  std::size_t plane_priors = 0;
};

struct Node::Impl {
  config::NodeConfig config;
  std::string build_label;
  SteadyTime started;
  const std::atomic<bool>* stop = nullptr;
  std::atomic<bool> stopping{false};
  std::atomic<link::NodeState> state{link::NodeState::kStarting};

  // Inputs and their queues.
  BoundedQueue<ScanSlot> scans;
  BoundedQueue<OdometrySlot> odometry;
  InputCounters lidar_counters, odometry_counters;
  std::unique_ptr<ReplayClock> replay_clock;
  bool lockstep() const { return config.pace == config::Pace::kLockstep; }

  // SLAM (owned by the SLAM thread once running).
  core::LocalMapper mapper;
  LatencyWindow keyframe_ms{4096}, wire_ms{4096};
  std::vector<SteadyTime> unpublished_keyframes;  ///< last-packet times since the last Publish
  mutable std::mutex status_mutex;
  SlamStatus slam_status;

  // The collaborative side: session under session_mutex (SLAM and collab threads).
  mutable std::mutex session_mutex;
  core::CollabSession session;
  std::unique_ptr<link::FleetLink> link;
  std::unique_ptr<link::RosPublisher> ros;  ///< SLAM thread only (Exchange)
  link::RosMapView ros_view;
  SteadyTime ros_cloud_last;
  bool ros_cloud_sent = false;
  void PublishRos();
  // Wall priors computed by the collab thread, applied by the SLAM thread at its next exchange.
  std::mutex priors_mutex;
  std::vector<core::PlanePrior> priors_mailbox, priors_scratch, priors_scratch_collab;
  // Every merge decision the session logged (drained after each Match, written at exit as
  // merge_log.csv); beyond kMaxMergeLog they are counted, not kept.
  static constexpr std::size_t kMaxMergeLog = 65536;
  std::vector<core::MergeLogEntry> merge_log, merge_log_scratch;
  std::uint64_t merge_log_sequence = 0, merge_log_dropped = 0;
  std::size_t priors_count = 0;
  std::uint64_t priors_generation = 0;
  std::uint64_t applied_priors_generation = 0;  ///< SLAM thread only
  // Set by the collab thread when a peer asked for our whole graph; the SLAM thread publishes.
  std::atomic<bool> publish_now{false};
  std::mutex wake_mutex;
  std::condition_variable wake_slam;
  // Resync requests we make (robots whose whole graph we need), read by the supervisor.
  mutable std::mutex resync_mutex;
  std::vector<std::uint16_t> resync_from;
  std::atomic<std::uint64_t> collab_changes{0};  ///< receptions that changed something, matches
  std::atomic<std::uint64_t> resends{0}, resyncs_requested{0};

  // Status LED (optional).
  std::unique_ptr<drivers::gpio::GpioProvider> gpio;
  std::unique_ptr<drivers::gpio::DigitalOutput> led_line;
  std::unique_ptr<drivers::gpio::StatusLed> led;

  // Checkpoint (optional): the journal, shared by the SLAM and collab threads.
  std::mutex journal_mutex;
  std::optional<JournalWriter> journal;
  std::atomic<std::uint64_t> journal_errors{0};
  /// Restored from the journal: recorded inputs skip what is already in the map.
  double resume_scans_after_s = -1, resume_odometry_after_s = -1;
  /// Live inputs after a resume: the odometry integration began again at identity, and the
  /// robot may have moved while the node was down. The new odometry is held in `new_odometry`
  /// until the first scan it covers is relocalised against the map (LocalMapper::Relocalise,
  /// searched from where the journal stopped, T_old_last at old_last_stamp_s, along the motion
  /// it had then); from then on it is mapped into the journal's odometry frame by T_odom_fix
  /// (SLAM thread only).
  bool reanchor_odometry = false;
  Eigen::Isometry3d T_old_last = Eigen::Isometry3d::Identity();
  double old_last_stamp_s = 0;
  core::OdometryBuffer new_odometry;
  std::optional<Eigen::Isometry3d> T_odom_fix;
  enum class Relocalising { kWait, kSkipScan, kDone };
  Relocalising RelocaliseOn(const ScanSlot& scan);
  /// Maps the held new odometry into the mapper (and the journal) through T_odom_fix.
  void ReleaseNewOdometry();
  void Journal(auto&& write) {
    if (!journal) return;
    std::lock_guard<std::mutex> lock(journal_mutex);
    if (!write(*journal)) journal_errors.fetch_add(1, std::memory_order_relaxed);
  }

  std::vector<std::thread> threads;
  // PrintStatus's previous counters (supervisor thread only), for rates.
  std::uint64_t status_last_scans = 0, status_last_odometry = 0;
  double status_last_t = 0;

  Impl(const config::NodeConfig& c) : config(c), scans(c.scan_queue), odometry(c.odometry_queue) {}

  bool ShouldStop() const { return stopping.load() || stop->load(); }

  // Thread loops (inputs.cpp, slam_loop.cpp, collab_loop.cpp).
  void LidarLoop();
  void OdometryLoop();
  void SlamLoop();
  void CollabLoop();
  // SLAM thread: Publish under the session lock, apply the newest priors.
  void Exchange();
  // Supervisor (node.cpp) and the end-of-run outputs (node_report.cpp).
  link::Telemetry MakeTelemetry() const;
  void PrintStatus(double since_start_s);
  void WriteOutputs();
  void WriteExports();  // node_exports.cpp: map.pcd, collab_graph.{csv,g2o}
  void PrintReport();
};

}  // namespace msgraphs::runtime
