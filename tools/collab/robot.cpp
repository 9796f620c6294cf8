// SPDX-License-Identifier: MIT
#include "robot.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <limits>
#include <span>

namespace msgraphs::tools::collab {
namespace {

namespace fs = std::filesystem;

void Advance(Robot& r) {
  r.pending = r.scans->Next();
  if (r.pending == nullptr)
    r.scans_done = true;
  else if (r.first_stamp < 0)
    r.first_stamp = r.pending->end_time.seconds_since_epoch();
}

void FeedOdometry(Robot& r, double until) {
  drivers::can_odometry::CandumpLine line;
  while (!r.odometry_done && r.mapper.odometry().newest_stamp() < until) {
    auto next = r.candump->Next(line);
    if (!next || !*next) {
      r.odometry_done = true;
      break;
    }
    if (!r.odometry.Add(line.frame, line.stamp)) continue;
    const auto& p = r.odometry.pose();
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() =
        Eigen::Quaterniond(p.T_odom_base.qw, p.T_odom_base.qx, p.T_odom_base.qy, p.T_odom_base.qz)
            .normalized()
            .toRotationMatrix();
    T.translation() << p.T_odom_base.x_m, p.T_odom_base.y_m, p.T_odom_base.z_m;
    static_cast<void>(r.mapper.AddOdometry(p.stamp.seconds_since_epoch(), T));
  }
}

}  // namespace

std::unique_ptr<Robot> OpenRobot(const std::string& dir_name,
                                 int index,
                                 double delay_s,
                                 std::size_t max_keyframes,
                                 bool timed,
                                 core::CollabSessionConfig session_config,
                                 std::string& error) {
  const fs::path dir(dir_name);
  auto r = std::make_unique<Robot>();
  r->index = index;
  r->delay_s = delay_s;
  r->timed = timed;
  r->scans = drivers::velodyne::RecordedScans::Open((dir / "velodyne.pcap").string());
  auto candump = drivers::can_odometry::CandumpFileReader::Open((dir / "odometry.log").c_str());
  if (!r->scans || !candump) {
    error = "cannot open " + dir.string();
    return nullptr;
  }
  r->candump.emplace(std::move(*candump));
  core::LocalMapperConfig config;
  if (max_keyframes > 0) {  // validated by Init
    // The factor store grows with it, at the defaults' ratio (16 a keyframe), never below.
    const std::size_t per_keyframe = config.graph.max_factors / config.graph.max_keyframes;
    config.graph.max_factors = std::max(config.graph.max_factors, per_keyframe * max_keyframes);
    config.graph.max_keyframes = max_keyframes;
  }
  session_config.robot = r->id();
  Status s = r->mapper.Init(config);
  if (s) s = r->session.Init(session_config, config.graph, -config.base_height_m);
  if (s) s = r->publisher.Init(session_config, config.graph, -config.base_height_m);
  if (s) s = r->exchange.Init(session_config);
  if (s) s = r->baseline.collab.Init({}, r->id());
  if (!s) {
    error = s.error().detail;
    return nullptr;
  }
  r->truth = ReadTum((dir / "ground_truth.tum").string());
  Advance(*r);
  return r;
}

double NextScanTime_s(const Robot& r) {
  return r.pending == nullptr
             ? std::numeric_limits<double>::infinity()
             : r.pending->end_time.seconds_since_epoch() - r.first_stamp + r.delay_s;
}

void ProcessNextScan(Robot& r) {
  // The tool's scratch, reused scan after scan (the mapper itself allocates nothing per scan).
  static std::vector<Eigen::Vector3f> points;
  static std::vector<float> times;
  points.clear();
  times.clear();
  for (const auto& p : r.pending->points) {
    points.emplace_back(p.x_m, p.y_m, p.z_m);
    times.push_back(static_cast<float>(p.time_offset_ns * 1e-9));
  }
  core::LidarScanView view{points, times, r.pending->start_time.seconds_since_epoch(),
                           r.pending->end_time.seconds_since_epoch()};
  FeedOdometry(r, view.end_s + 0.05);
  if (!r.timed) {
    static_cast<void>(r.mapper.AddScan(view));
    Advance(r);
    return;
  }
  const auto sweep_start = std::chrono::steady_clock::now();
  const auto outcome = r.mapper.AddScan(view, &r.timing);
  if (outcome && *outcome == core::ScanOutcome::kNotKeyframe) {
    r.timing.Sweep(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() -
                                                             sweep_start)
                       .count());
  }
  r.solver.Follow(r.mapper);
  Advance(r);
}

std::vector<StampedPose> Keyframes(const Robot& r) {
  std::vector<StampedPose> kf;
  const core::SGraph& g = r.mapper.graph();
  for (std::uint32_t k = g.FirstKeyframe(); k != core::SGraph::kNoKeyframe; k = g.NextKeyframe(k))
    kf.push_back({g.keyframe_stamp(k), g.keyframe_pose(k)});
  return kf;
}

}  // namespace msgraphs::tools::collab
