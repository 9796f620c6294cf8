// SPDX-License-Identifier: MIT
// One robot of an msgraphs_collab mission: its recording (VLP-16 pcap, candump odometry, ground
// truth), its local S-Graph and its CollabSession, fed scan by scan in lock-step by mission
// time. A robot's mission time is its scan stamps from its first scan on, plus its start delay.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "msgraphs/core/collab/collab_publisher.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/collab/room_matcher.hpp"
#include "msgraphs/core/descriptors/scan_context.hpp"
#include "msgraphs/core/graph/collaborative_graph.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/can_odometry/odometry_stream.hpp"
#include "msgraphs/drivers/velodyne/recorded_scans.hpp"
#include "msgraphs/tools/keyframe_timing.hpp"
#include "msgraphs/tools/solver_thread.hpp"
#include "msgraphs/tools/tum.hpp"

namespace msgraphs::tools::collab {

/// The keyframe-level baseline's state of one robot (keyframe_baseline.hpp).
struct KeyframeBaselineState {
  /// The newest keyframe stamp sent (keyframes are walked in time order, not slot order).
  double last_sent_stamp_s = -std::numeric_limits<double>::infinity();
  std::map<std::uint32_t, core::ScanContext> own_keyframes;
  /// Received: (sender index, keyframe) -> its descriptor and the sender's pose at the time.
  std::map<std::pair<int, std::uint32_t>, std::pair<core::ScanContext, Eigen::Isometry3d>>
      peer_keyframes;
  std::set<std::pair<int, std::uint32_t>> tried_keyframes;
  std::map<int, std::vector<core::RoomMatch>> matches;  ///< per peer index
  std::map<int, std::vector<std::uint32_t>> consistent;
  core::CollaborativeGraph collab;  ///< origin measurements only
  std::uint64_t proposals = 0, rejected_fine = 0, rejected_consistency = 0;
};

struct Robot {
  int index = 0;  ///< 0-based; robot ids on the wire are index + 1
  std::uint16_t id() const { return static_cast<std::uint16_t>(index + 1); }
  std::unique_ptr<drivers::velodyne::RecordedScans> scans;
  std::optional<drivers::can_odometry::CandumpFileReader> candump;
  drivers::can_odometry::OdometryStream odometry =
      drivers::can_odometry::OdometryStream::Create({}).value();
  bool odometry_done = false, scans_done = false;
  const drivers::velodyne::Scan* pending = nullptr;
  double first_stamp = -1;
  double delay_s = 0;                 ///< this robot's mission starts this much later
  const char* delay_source = "none";  ///< "none", "mission.txt" or "--delay-s"
  core::LocalMapper mapper;
  core::CollabSession session;
  core::CollabPublisher publisher;  ///< the own map for the session (one thread here: PublishNow)
  core::CollabExchange exchange;
  /// Every merge decision its session logged (drained after each exchange), for --out.
  std::vector<core::MergeLogEntry> merge_log;
  KeyframeBaselineState baseline;
  std::vector<StampedPose> truth;  ///< ground_truth.tum as read (empty when absent)
  /// --timing: its mapper's per-stage keyframe timing is recorded, and each full solve its
  /// mapper begins runs on a thread of its own, as the node's solver thread does. Off, the
  /// mapper runs each at the keyframe it applies it at, on the mission's thread: a solve then
  /// never competes with the robots for the 2 cores, so no time limit (the local solve's 50 ms,
  /// a full solve's 2 s) is reached for want of a core, and the maps are the same run after run.
  bool timed = false;
  KeyframeTiming timing;
  SolverThread solver;  ///< declared last: joined before the mapper goes
};

/// Opens robot `index`'s recording in `dir` (velodyne.pcap, odometry.log, ground_truth.tum) and
/// initialises its mapper, session and baseline graph. nullptr with `error` set on failure.
/// `max_keyframes`: the S-Graph's keyframe store (0: the mapper's default); `timed`: Robot::timed.
std::unique_ptr<Robot> OpenRobot(const std::string& dir,
                                 int index,
                                 double delay_s,
                                 std::size_t max_keyframes,
                                 bool timed,
                                 core::CollabSessionConfig session_config,
                                 std::string& error);

/// The mission time of the robot's next scan (its end), or +inf when it has none left.
double NextScanTime_s(const Robot& r);
/// Feeds the robot's next scan (and the odometry up to just past its end) to its mapper.
void ProcessNextScan(Robot& r);
/// The robot's active keyframes (stamp: its recording clock; pose: its map frame), by stamp.
std::vector<StampedPose> Keyframes(const Robot& r);

}  // namespace msgraphs::tools::collab
