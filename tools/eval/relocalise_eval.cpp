// SPDX-License-Identifier: MIT
// msgraphs_relocalise_eval: how often a restarted node finds its robot again, and how often it
// is wrong. One robot's recording is mapped in lock-step (as msgraphs_slam does); at each stop
// the node is taken to have been killed there: its journal holds the map and the odometry up to
// the stop. For each downtime, the first scan ending that long after the stop is relocalised
// with the node's own search (core::RestartPrediction, LocalMapper::Relocalise), its new
// odometry integration begun at identity as the node's is. The answer is judged against the
// ground truth at the scan's end, relative to the keyframe truly nearest the robot (the map's
// own drift elsewhere is not the relocalisation's):
//   right    accepted, within the scan matcher's max_correction_m and 5 degrees
//            (tracking takes up the rest),
//   wrong    accepted, beyond them: the map is corrupted from there on,
//   refused  no answer (the node resumes on the motion the robot had; that fallback's error is
//            printed too).
// The mapper goes on mapping after each stop as if nothing had happened.
//
//   msgraphs_relocalise_eval --run DIR --robot N [--stops K] [--downtimes 2,4,6]
//                            [--max-speed-mps 1.6] [--first-s 10] [--max-seen-through F]
//                            [--verbose]
// --max-seen-through overrides RelocaliseSearch::max_seen_through (1 turns the test off).
//
// Prints one line per relocalisation and a summary ("relocalise: N right, N wrong, N refused");
// exit status 0, or 1 when one was wrong, 2 on bad arguments or input.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/core/slam/odometry_buffer.hpp"
#include "msgraphs/core/slam/restart_prediction.hpp"
#include "msgraphs/drivers/velodyne/recorded_scans.hpp"
#include "msgraphs/tools/candump_odometry.hpp"
#include "msgraphs/tools/truth_pairing.hpp"
#include "msgraphs/tools/tum.hpp"

namespace {

using namespace msgraphs;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct ScanCopy {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> times;
  double start_s = 0, end_s = 0;
  core::LidarScanView view() const { return {points, times, start_s, end_s}; }
};

void Copy(const drivers::velodyne::Scan& scan, ScanCopy& out) {
  out.points.clear();
  out.times.clear();
  for (const auto& p : scan.points) {
    out.points.emplace_back(p.x_m, p.y_m, p.z_m);
    out.times.push_back(static_cast<float>(p.time_offset_ns * 1e-9));
  }
  out.start_s = scan.start_time.seconds_since_epoch();
  out.end_s = scan.end_time.seconds_since_epoch();
}

constexpr std::uint32_t kNoKeyframe = 0xFFFFFFFFu;

double Yaw(const Eigen::Matrix3d& R) { return std::atan2(R(1, 0), R(0, 0)); }
double Deg(double rad) { return rad * 180.0 / std::numbers::pi; }

std::vector<double> ParseList(const std::string& text) {
  std::vector<double> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(std::atof(item.c_str()));
  return out;
}

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::lround(q * static_cast<double>(v.size() - 1)))];
}

}  // namespace

int main(int argc, char** argv) {
  std::string run;
  int robot = 1;
  int stops = 8;
  std::vector<double> downtimes{2, 4, 6};
  double max_speed_mps = 1.6, first_s = 10, max_seen_through = -1;
  bool verbose = false;
  // Options that take a value, each with what it sets.
  const std::map<std::string, std::function<void(const char*)>> takes_value = {
      {"--run", [&](const char* v) { run = v; }},
      {"--robot", [&](const char* v) { robot = std::atoi(v); }},
      {"--stops", [&](const char* v) { stops = std::atoi(v); }},
      {"--downtimes", [&](const char* v) { downtimes = ParseList(v); }},
      {"--max-speed-mps", [&](const char* v) { max_speed_mps = std::atof(v); }},
      {"--max-seen-through", [&](const char* v) { max_seen_through = std::atof(v); }},
      {"--first-s", [&](const char* v) { first_s = std::atof(v); }},
  };
  for (int i = 1; i < argc; ++i) {
    const auto option = takes_value.find(argv[i]);
    if (option != takes_value.end() && i + 1 < argc) {
      option->second(argv[++i]);
    } else if (std::string(argv[i]) == "--verbose") {
      verbose = true;
    } else {
      std::fprintf(stderr,
                   "usage: msgraphs_relocalise_eval --run DIR --robot N [--stops K] "
                   "[--downtimes 2,4,6] [--max-speed-mps 1.6] [--first-s 10] [--max-seen-through F] "
                   "[--verbose]\n");
      return 2;
    }
  }
  std::sort(downtimes.begin(), downtimes.end());
  // The restarted node's odometry begins half a second before its first scan, after the stop.
  if (stops < 1 || downtimes.empty() || !(downtimes.front() >= 0.6) ||
      !std::all_of(downtimes.begin(), downtimes.end(), [](double d) { return std::isfinite(d); }) ||
      !(max_speed_mps > 0) || !std::isfinite(max_speed_mps) || !(first_s >= 0)) {
    std::fprintf(stderr, "relocalise: --stops >= 1, --downtimes of 0.6 s or more, --max-speed-mps > 0\n");
    return 2;
  }
  const fs::path dir = fs::path(run) / ("robot" + std::to_string(robot));
  const tools::TruthTrajectory truth(tools::ReadTum((dir / "ground_truth.tum").string()));
  if (run.empty() || !fs::exists(dir / "velodyne.pcap") || !fs::exists(dir / "odometry.log") ||
      truth.samples().size() < 2) {
    std::fprintf(stderr, "relocalise: %s needs velodyne.pcap, odometry.log and ground_truth.tum\n",
                 dir.c_str());
    return 2;
  }
  // Stops spread evenly after first_s.
  const double t0 = truth.samples().front().t, t1 = truth.samples().back().t;
  const double span_s = t1 - downtimes.back() - 1.0 - (t0 + first_s);
  if (span_s <= 0) {
    std::fprintf(stderr, "relocalise: the recording is too short for --first-s and --downtimes\n");
    return 2;
  }
  const double spacing_s = span_s / stops;

  core::LocalMapperConfig config;
  core::LocalMapper mapper;
  if (auto s = mapper.Init(config); !s) {
    std::fprintf(stderr, "relocalise: %s\n", s.error().detail);
    return 2;
  }
  auto scans = drivers::velodyne::RecordedScans::Open((dir / "velodyne.pcap").string());
  auto ahead_scans = drivers::velodyne::RecordedScans::Open((dir / "velodyne.pcap").string());
  auto odometry = tools::CandumpOdometry::Open((dir / "odometry.log").c_str());
  auto ahead_odometry = tools::CandumpOdometry::Open((dir / "odometry.log").c_str());
  if (!scans || !ahead_scans || !odometry || !ahead_odometry) {
    std::fprintf(stderr, "relocalise: cannot open the recording in %s\n", dir.c_str());
    return 2;
  }
  // The encoders read ahead of the mapper: the restarted node's odometry.
  core::OdometryBuffer future;
  future.Init(1 << 16, 0.1);
  const auto to_mapper = [&](double t, const Eigen::Isometry3d& T) {
    static_cast<void>(mapper.AddOdometry(t, T));
  };
  const auto to_future = [&](double t, const Eigen::Isometry3d& T) {
    static_cast<void>(future.Add(t, T));
  };

  ScanCopy scan, later;
  std::size_t right = 0, wrong = 0, refused = 0, refused_fallback_within = 0, skipped = 0;
  std::size_t right_segment = 0, right_reach = 0, wrong_segment = 0, wrong_reach = 0;
  std::vector<double> right_error_m, took_ms;
  std::printf("stop_s down_s moved_m result error_m error_deg fitness_m2 seen_through search took_ms detail\n");
  int stop = 0;
  double next_stop_s = t0 + first_s + spacing_s;
  const auto map_scan = [&](const ScanCopy& s) {
    odometry->Until(s.end_s + 0.05, to_mapper);
    static_cast<void>(mapper.AddScan(s.view()));
    // The background full solve, run at once (the map does not depend on when it runs).
    if (core::SGraphSolveJob* job = mapper.background_solve(); job != nullptr && job->TryClaim())
      job->Run();
  };
  while (const drivers::velodyne::Scan* next = scans->Next()) {
    Copy(*next, scan);
    if (scan.end_s <= next_stop_s || stop >= stops) {
      map_scan(scan);
      continue;
    }
    // The node is killed here (its journal ends with the last odometry the mapper has).
    ++stop;
    const double stop_s = mapper.odometry().newest_stamp();
    const auto last = mapper.odometry().At(stop_s);
    const core::SGraph& graph = mapper.graph();
    std::uint32_t last_keyframe = kNoKeyframe;
    for (std::uint32_t k = 0; k < graph.keyframe_slots(); ++k) {
      if (graph.keyframe_active(k) && (last_keyframe == kNoKeyframe ||
                                       graph.keyframe_stamp(k) >= graph.keyframe_stamp(last_keyframe)))
        last_keyframe = k;
    }
    const auto truth_last =
        truth.At(last_keyframe == kNoKeyframe ? 0.0 : graph.keyframe_stamp(last_keyframe));
    if (!last || last_keyframe == kNoKeyframe || !truth_last.ok) {
      skipped += downtimes.size();
      map_scan(scan);
      next_stop_s += spacing_s;
      continue;
    }
    const core::RestartPrediction prediction(mapper.odometry(), last->T_odom_base, stop_s);
    // The map frame from the odometry frame, at the last keyframe (the node's relocalised pose
    // is used so: the odometry frame agrees with the map there).
    const Eigen::Isometry3d T_map_odom =
        graph.keyframe_pose(last_keyframe) * mapper.keyframe_odometry(last_keyframe).inverse();
    if (later.end_s >= stop_s + downtimes.front()) {
      // The stops are closer than the downtimes: read the recording ahead again from its start.
      ahead_scans = drivers::velodyne::RecordedScans::Open((dir / "velodyne.pcap").string());
      ahead_odometry = tools::CandumpOdometry::Open((dir / "odometry.log").c_str());
      if (!ahead_scans || !ahead_odometry) {
        std::fprintf(stderr, "relocalise: cannot reopen the recording in %s\n", dir.c_str());
        return 2;
      }
      future.Clear();
      later.end_s = 0;
    }
    for (const double down_s : downtimes) {
      // The first scan ending down_s after the stop; the new integration begins at identity
      // half a second before it (the node started, replayed its journal, then took a scan).
      while (later.end_s < stop_s + down_s) {
        const drivers::velodyne::Scan* a = ahead_scans->Next();
        if (a == nullptr) break;
        Copy(*a, later);
      }
      if (later.end_s < stop_s + down_s) {  // the recording ended
        ++skipped;
        continue;
      }
      ahead_odometry->Until(later.end_s + 0.05, to_future);
      const auto origin = future.At(later.start_s - 0.5);
      const auto at_start = future.At(later.start_s), at_end = future.At(later.end_s);
      const auto truth_end = truth.At(later.end_s), truth_stop = truth.At(stop_s);
      if (!origin || !at_start || !at_end || !truth_end.ok || !truth_stop.ok) {
        ++skipped;
        continue;
      }
      const Eigen::Isometry3d T_new_start = origin->T_odom_base.inverse() * at_start->T_odom_base;
      const Eigen::Isometry3d T_new_end = origin->T_odom_base.inverse() * at_end->T_odom_base;
      core::RelocaliseSearch search = prediction.Search(later.end_s, max_speed_mps);
      if (max_seen_through >= 0) search.max_seen_through = max_seen_through;
      const auto began = Clock::now();
      auto found = mapper.Relocalise(later.view(), T_new_start, T_new_end, search);
      const double ms = std::chrono::duration<double, std::milli>(Clock::now() - began).count();
      took_ms.push_back(ms);
      const double moved_m =
          (truth_end.T.translation() - truth_stop.T.translation()).head<2>().norm();
      // The node's pose: the answer, or the motion kept on through the downtime.
      const double fallback_s = std::max(0.0, later.start_s - 0.5 - stop_s);
      const Eigen::Isometry3d T_odom_base =
          found ? found->T_odom_base : prediction.KeptOn(fallback_s) * T_new_end;
      // Judged from the keyframe that was truly nearest the robot, as the truth went from
      // there: what the robot maps next is laid against the map there, and the map's own drift
      // elsewhere (a few centimetres, decimetres before a loop closes) is not the answer's.
      std::uint32_t near = last_keyframe;
      auto truth_near = truth_last;
      double near_m = std::numeric_limits<double>::infinity();
      for (std::uint32_t k = 0; k < graph.keyframe_slots(); ++k) {
        if (!graph.keyframe_active(k)) continue;
        const auto at = truth.At(graph.keyframe_stamp(k));
        if (!at.ok) continue;
        const double d = (at.T.translation() - truth_end.T.translation()).norm();
        if (d < near_m) {
          near_m = d;
          near = k;
          truth_near = at;
        }
      }
      const Eigen::Isometry3d T_keyframe_estimate =
          graph.keyframe_pose(near).inverse() * T_map_odom * T_odom_base;
      const Eigen::Isometry3d T_keyframe_truth = truth_near.T.inverse() * truth_end.T;
      const Eigen::Isometry3d T_error = T_keyframe_truth.inverse() * T_keyframe_estimate;
      const double error_m =
          (T_keyframe_estimate.translation() - T_keyframe_truth.translation()).head<2>().norm();
      const double error_deg = std::abs(Deg(Yaw(T_error.linear())));
      const bool within = error_m <= config.max_correction_m && error_deg <= 5.0;
      const char* result;
      if (!found) {
        result = "refused";
        ++refused;
        if (within) ++refused_fallback_within;
      } else if (within) {
        result = "right";
        ++right;
        ++(found->wide ? right_reach : right_segment);
        right_error_m.push_back(error_m);
      } else {
        result = "WRONG";
        ++wrong;
        ++(found->wide ? wrong_reach : wrong_segment);
      }
      if (verbose || !found || !within) {
        std::printf("%.1f %.1f %.2f %s %.3f %.1f %.4f %.3f %s %.0f %s\n", stop_s - t0, down_s, moved_m,
                    result, error_m, error_deg, found ? found->fitness_m2 : 0.0,
                    found ? found->seen_through : 0.0,
                    found ? (found->wide ? "reach" : "segment") : "-", ms,
                    found ? "" : found.error().detail);
      }
    }
    map_scan(scan);
    next_stop_s += spacing_s;
  }
  static_cast<void>(mapper.Finish());
  std::printf(
      "relocalise: %zu right (%zu on the predicted segment, %zu within reach; error p50 %.3f m, "
      "max %.3f m), %zu wrong (%zu on the segment, %zu within reach), %zu refused (the motion "
      "kept on lands within %.2f m for %zu of them), %zu skipped; time p50 %.0f ms, max %.0f ms\n",
      right, right_segment, right_reach, Percentile(right_error_m, 0.5),
      Percentile(right_error_m, 1.0), wrong, wrong_segment, wrong_reach, refused,
      config.max_correction_m,
      refused_fallback_within, skipped, Percentile(took_ms, 0.5), Percentile(took_ms, 1.0));
  return wrong > 0 ? 1 : 0;
}
