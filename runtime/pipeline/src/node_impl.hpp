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

#include "msgraphs/core/collab/collab_publisher.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/drivers/gpio/gpio.hpp"
#include "msgraphs/drivers/gpio/status_led.hpp"
#include "msgraphs/runtime/link/fleet_link.hpp"
#include "msgraphs/runtime/link/ros_publisher.hpp"
#include "msgraphs/runtime/pipeline/bounded_queue.hpp"
#include "msgraphs/runtime/pipeline/handover.hpp"
#include "msgraphs/runtime/pipeline/checkpoint.hpp"
#include "msgraphs/runtime/pipeline/latency_window.hpp"
#include "msgraphs/runtime/pipeline/node.hpp"
#include "msgraphs/runtime/pipeline/replay_clock.hpp"
#include "solver_worker.hpp"

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

/// What the SLAM thread reports after each scan and the collab thread after each exchange and
/// Match (under `status_mutex`).
struct SlamStatus {
  std::uint64_t scans = 0, keyframes = 0, no_odometry = 0;
  std::uint32_t walls = 0, rooms = 0;
  std::uint32_t graph_version = 0;  ///< the distilled version we have sent
  double keyframe_p50_ms = 0, keyframe_p99_ms = 0;
  /// The keyframes whose end took a checkpoint snapshot (their latency holds the mapper's Save).
  double snapshot_keyframe_p50_ms = 0, snapshot_keyframe_max_ms = 0;
  std::uint64_t snapshot_keyframes = 0;
  double wire_p50_ms = 0, wire_p99_ms = 0, wire_max_ms = 0;  ///< last packet -> on the wire
  /// The SLAM thread's time in an exchange (priors, Prepare, the hand-over, the ROS view).
  double exchange_p50_ms = 0, exchange_p99_ms = 0, exchange_max_ms = 0;
  /// Exchanges not prepared because the last one was not taken yet (tried again after each scan,
  /// each try counted).
  std::uint64_t exchanges_deferred = 0;
  /// Tries that found the exchange's wall marginals still computing on the marginals thread
  /// (the exchange goes out at a later scan's try).
  std::uint64_t exchanges_awaiting_marginals = 0;
  /// From an exchange's first try to its send, while its marginals computed (wall time).
  double marginals_wait_p50_ms = 0, marginals_wait_p99_ms = 0, marginals_wait_max_ms = 0;
  double match_p50_ms = 0, match_p99_ms = 0, match_max_ms = 0;  ///< the collab thread's Match
  // Written by the collab thread from the session (PublishCollabStatus), so that telemetry and
  // status lines never wait for a Match either.
  struct PeerLine {
    std::uint16_t robot = 0;
    bool merged = false;
    std::uint64_t bytes_in = 0;
  };
  static constexpr std::size_t kPeerLines = 32;  ///< Telemetry::merged holds as many
  std::array<PeerLine, kPeerLines> peer_lines{};
  std::size_t peer_count = 0;
  std::uint64_t malformed = 0;
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
  SolverWorker solver;  ///< runs the mapper's full solve (its own thread)
  SolverWorker marginals_solver;  ///< runs the distiller's wall marginals (its own thread)
  LatencyWindow keyframe_ms{4096};  ///< SLAM thread
  LatencyWindow snapshot_keyframe_ms{256};  ///< SLAM thread: the keyframes that took a snapshot
  LatencyWindow wire_ms{4096};      ///< collab thread, under status_mutex
  std::vector<SteadyTime> unpublished_keyframes;  ///< last-packet times since the last Publish
  mutable std::mutex status_mutex;
  SlamStatus slam_status;

  // The collaborative side: the session under session_mutex (the collab thread; the supervisor
  // after the threads ended). The SLAM thread never takes it.
  mutable std::mutex session_mutex;
  core::CollabSession session;
  // The own map for the session: prepared by the SLAM thread (publisher), ingested by the collab
  // thread (handover.hpp: while the last one still waits, the SLAM thread prepares nothing and
  // tries again after its next scan: exchanges_deferred).
  core::CollabPublisher publisher;  ///< SLAM thread only
  bool marginals_begun = false;     ///< this exchange's first step is done (SLAM thread)
  bool marginals_job_begun = false; ///< ... and began a marginals job (SLAM thread)
  SteadyTime marginals_begun_at, marginals_done_at;  ///< first try, first try that found it done
  double exchange_busy_ms = 0;      ///< the SLAM thread's time in this exchange's tries so far
  struct ExchangeSlot {
    core::CollabExchange x;
    std::vector<SteadyTime> keyframes;  ///< last-packet times of the keyframes it first carries
    core::CollabPublisherStats publisher;  ///< the publisher's, when it was prepared
  };
  Handover<ExchangeSlot> exchanges;
  /// Collab thread (and the supervisor once the threads ended): the posted exchange, if any,
  /// into the session and out through the link.
  void IngestExchange();
  // Peers' place requests the session let through, for the next exchange (collab -> SLAM; the
  // collab thread takes requests_mutex inside session_mutex, the SLAM thread alone).
  std::mutex requests_mutex;
  BoundedVector<core::PlaceRequest> requests_mailbox;
  // The merged robots' walls, rooms and origins in this robot's frame, for the ROS view
  // (collab -> SLAM; the own map the SLAM thread draws from the publisher).
  std::mutex ros_fleet_mutex;
  link::RosMapView ros_fleet, ros_fleet_scratch;
  /// Collab thread, under session_mutex: ros_fleet from the session.
  void RefreshRosFleet();
  /// Collab thread, under session_mutex: the peers' lines of SlamStatus.
  void PublishCollabStatus();
  LatencyWindow exchange_ms{4096};  ///< SLAM thread
  LatencyWindow marginals_wait_ms{4096};  ///< SLAM thread
  LatencyWindow match_ms{4096};     ///< collab thread
  std::unique_ptr<link::FleetLink> link;
  std::unique_ptr<link::RosPublisher> ros;  ///< SLAM thread only (Exchange); set before the threads
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

  // Checkpoint (optional): the journal in generations, shared by the SLAM and collab threads,
  // and its writer thread's snapshots.
  std::unique_ptr<Checkpoint> checkpoint;
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
    if (checkpoint) checkpoint->Journal(write);
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
  /// SLAM thread: priors in, the own map prepared and posted for the collab thread; false when
  /// the last exchange was not taken yet (nothing prepared: try again after the next scan).
  bool Exchange();
  // Supervisor (node.cpp) and the end-of-run outputs (node_report.cpp).
  link::Telemetry MakeTelemetry() const;
  void PrintStatus(double since_start_s);
  void WriteOutputs();
  void WriteExports();  // node_exports.cpp: map.pcd, collab_graph.{csv,g2o}
  void PrintReport();
};

}  // namespace msgraphs::runtime
