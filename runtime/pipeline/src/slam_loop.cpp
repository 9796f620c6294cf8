// SPDX-License-Identifier: MIT
// The SLAM thread: odometry and scans into the local S-Graph; every exchange period (sensor
// time) the own map is prepared for the session (distilled graph, room descriptors, free space,
// place clouds) and handed to the collab thread, and the newest wall priors from the other
// robots come in. After the inputs end it keeps serving: it
// publishes again when a peer asks for a resync or new priors arrive.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "msgraphs/core/slam/restart_prediction.hpp"
#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/realtime.hpp"
#include "node_impl.hpp"

namespace msgraphs::runtime {

namespace {

constexpr Duration kWait = Duration::FromMilliseconds(20);
/// Live inputs: a scan waits this long for the odometry that covers its end.
constexpr Duration kOdometryPatience = Duration::FromMilliseconds(500);
/// A scan needs odometry up to its end plus this (the mapper interpolates).
constexpr double kOdometryMargin_s = 0.05;

}  // namespace

// Returns false when the exchange cannot go out yet: its walls' marginals are still computing on
// the marginals thread, or the last exchange still waits for the collab thread (busy in Match).
// The caller tries again after its next scan; this thread never waits for either.
bool Node::Impl::Exchange() {
  const SteadyTime t0 = platform::SteadyNow();
  const auto add_busy = [&] { exchange_busy_ms += (platform::SteadyNow() - t0).seconds() * 1e3; };
  if (config.feedback) {
    bool fresh = false;
    {
      std::lock_guard<std::mutex> lock(priors_mutex);
      if (priors_generation != applied_priors_generation) {
        applied_priors_generation = priors_generation;
        std::copy_n(priors_mailbox.begin(), priors_count, priors_scratch.begin());
        fresh = true;
      }
    }
    if (fresh) {
      const std::span<const core::PlanePrior> priors(priors_scratch.data(), priors_count);
      static_cast<void>(mapper.SetPlanePriors(priors));
      Journal([&](JournalWriter& j) { return static_cast<bool>(j.Priors(priors)); });
      // After the inputs ended no keyframe will trigger the full solve: run it here.
      if (state.load() == link::NodeState::kInputDone) {
        static_cast<void>(mapper.Finish());
        Journal([](JournalWriter& j) { return static_cast<bool>(j.Finish()); });
      }
    }
  }
  // Mapping: the walls' marginal covariances (a factorisation of the whole graph, over a second
  // at 4,000 keyframes) are computed on the marginals thread, for the map as it is at the
  // exchange's first try; the exchange goes out at the first try that finds them done, a few
  // scans later. Once the inputs ended nothing waits on this thread: they are computed in the
  // exchange, for the final map.
  const bool background =
      config.marginals_in_background && state.load() != link::NodeState::kInputDone;
  if (background) {
    if (!marginals_begun) {
      marginals_job_begun = publisher.BeginMarginals(mapper);
      if (marginals_job_begun) marginals_solver.Offer(publisher.marginals_job());
      marginals_begun = true;
      marginals_begun_at = t0;
    }
    if (publisher.marginals_ready()) {
      if (marginals_job_begun && marginals_done_at < marginals_begun_at) marginals_done_at = t0;
    } else {
      add_busy();
      std::lock_guard<std::mutex> lock(status_mutex);
      ++slam_status.exchanges_awaiting_marginals;
      return false;
    }
  }
  ExchangeSlot* slot = exchanges.Begin();
  if (slot == nullptr) {
    add_busy();
    std::lock_guard<std::mutex> lock(status_mutex);
    ++slam_status.exchanges_deferred;
    return false;
  }
  // The slot is neither posted nor being ingested: this thread's alone until it is posted.
  slot->x.requests.clear();
  {
    std::lock_guard<std::mutex> lock(requests_mutex);
    for (const core::PlaceRequest& q : requests_mailbox) static_cast<void>(slot->x.requests.try_push_back(q));
    requests_mailbox.clear();
  }
  publisher.Prepare(mapper, slot->x,
                    background ? core::MarginalsTiming::kBackground : core::MarginalsTiming::kNow);
  // From the first try to the first that found the job done (a wait for a free slot after it
  // is exchanges_deferred's).
  if (background && marginals_job_begun) marginals_wait_ms.Add((marginals_done_at - marginals_begun_at).seconds() * 1e3);
  marginals_begun = false;
  slot->publisher = publisher.stats();
  slot->keyframes.clear();
  slot->keyframes.insert(slot->keyframes.end(), unpublished_keyframes.begin(), unpublished_keyframes.end());
  unpublished_keyframes.clear();
  const core::DistilledGraph& g = publisher.graph();
  exchanges.Post(slot);
  // The collab thread takes it between its receive rounds (at most kReceiveWait) and Matches.
  PublishRos();
  // The SLAM thread's time in the exchange, over its tries; timed while mapping: once the
  // inputs ended nothing waits on this thread (and the exchange computes the marginals itself).
  add_busy();
  if (state.load() != link::NodeState::kInputDone) exchange_ms.Add(exchange_busy_ms);
  exchange_busy_ms = 0;
  std::lock_guard<std::mutex> lock(status_mutex);
  slam_status.walls = static_cast<std::uint32_t>(g.walls.size());
  slam_status.rooms = static_cast<std::uint32_t>(g.rooms.size());
  slam_status.plane_priors = mapper.stats().plane_priors;
  slam_status.exchange_p50_ms = exchange_ms.Percentile(0.5);
  slam_status.exchange_p99_ms = exchange_ms.Percentile(0.99);
  slam_status.exchange_max_ms = exchange_ms.Percentile(1.0);
  slam_status.marginals_wait_p50_ms = marginals_wait_ms.Percentile(0.5);
  slam_status.marginals_wait_p99_ms = marginals_wait_ms.Percentile(0.99);
  slam_status.marginals_wait_max_ms = marginals_wait_ms.Percentile(1.0);
  return true;
}

Node::Impl::Relocalising Node::Impl::RelocaliseOn(const ScanSlot& scan) {
  const auto at_start = new_odometry.At(scan.start_s);
  const auto at_end = new_odometry.At(scan.end_s);
  if (!at_start || !at_end) {
    const bool later = (!at_end && at_end.error().code == Errc::kWouldBlock);
    return later && (at_start || at_start.error().code != Errc::kNotFound)
               ? Relocalising::kWait
               : Relocalising::kSkipScan;
  }
  // Where to look: from where the journal stopped, along the motion the robot had then, and
  // failing that anywhere it could have walked to at its top speed (core/slam/restart_prediction.hpp).
  const core::RestartPrediction prediction(mapper.odometry(), T_old_last, old_last_stamp_s);
  const core::RelocaliseSearch search =
      prediction.Search(scan.end_s, config.relocalise_max_speed_mps);
  const double since_s = scan.end_s - old_last_stamp_s;
  const SteadyTime t0 = platform::SteadyNow();
  core::LidarScanView view{scan.points, scan.time_offset_s, scan.start_s, scan.end_s};
  auto found = mapper.Relocalise(view, at_start->T_odom_base, at_end->T_odom_base, search);
  const double took_s = (platform::SteadyNow() - t0).seconds();
  Eigen::Isometry3d T_odom_base_now;
  if (found) {
    T_odom_base_now = found->T_odom_base;
    const Eigen::Isometry3d moved = T_old_last.inverse() * T_odom_base_now;
    std::printf(
        "relocalised after the restart: the robot moved %.2f m and turned %.1f deg while the node "
        "was down (%.1f s); fitness %.4f m2, %zu seeds scored%s, %zu registered, %.2f s\n",
        moved.translation().head<2>().norm(),
        Eigen::AngleAxisd(moved.linear()).angle() * 180.0 / 3.14159265358979, since_s,
        found->fitness_m2, found->candidates,
        found->wide ? " (off the predicted path: searched within reach)" : "", found->registrations,
        took_s);
  } else {
    // Nothing aligned (a place not mapped yet, or one the map saw only from afar): the robot
    // is taken to have kept its motion through the downtime (a walking robot was most likely
    // still walking; one that stood still had no motion to keep); scan matching then takes
    // up the rest within max_correction_m.
    const double down_s = std::max(0.0, new_odometry.stamp(0) - old_last_stamp_s);
    T_odom_base_now = prediction.KeptOn(down_s) * new_odometry.pose(0).inverse() * at_end->T_odom_base;
    std::printf("WARNING: relocalisation after the restart failed (%s); resuming %.1f s after "
                "the last journaled pose with the motion the robot had then (%.2f m)\n",
                found.error().detail, since_s,
                (T_old_last.inverse() * T_odom_base_now).translation().head<2>().norm());
  }
  std::fflush(stdout);
  T_odom_fix = T_odom_base_now * at_end->T_odom_base.inverse();
  return Relocalising::kDone;
}

void Node::Impl::ReleaseNewOdometry() {
  for (std::size_t i = 0; i < new_odometry.size(); ++i) {
    const double stamp_s = new_odometry.stamp(i);
    const Eigen::Isometry3d T_odom_base = *T_odom_fix * new_odometry.pose(i);
    static_cast<void>(mapper.AddOdometry(stamp_s, T_odom_base));
    Journal([&](JournalWriter& j) { return static_cast<bool>(j.Odometry(stamp_s, T_odom_base)); });
  }
  new_odometry.Clear();
}

void Node::Impl::SlamLoop() {
  static_cast<void>(platform::SetCurrentThreadName("msg-slam"));
  double next_exchange_s = -1;
  bool exchange_owed = false;
  SteadyTime next_sync = platform::SteadyNow() + Duration::FromSeconds(config.checkpoint_sync_s);
  const double inf = std::numeric_limits<double>::infinity();
  // Odometry into the mapper: in lock-step only what the next scan needs (the rest waits in
  // the queue, holding the reader back), otherwise everything that has arrived.
  auto drain_odometry = [&](double horizon_s) {
    while (OdometrySlot* o = odometry.Front(Duration())) {
      if (o->stamp_s > horizon_s) break;
      Eigen::Isometry3d T_odom_base = o->T_odom_base;
      if (reanchor_odometry) {
        if (!T_odom_fix) {
          // Held until a scan is relocalised (RelocaliseOn); refused samples are counted there.
          static_cast<void>(new_odometry.Add(o->stamp_s, o->T_odom_base));
          odometry.Pop();
          continue;
        }
        T_odom_base = *T_odom_fix * o->T_odom_base;
      }
      static_cast<void>(mapper.AddOdometry(o->stamp_s, T_odom_base));
      Journal(
          [&](JournalWriter& j) { return static_cast<bool>(j.Odometry(o->stamp_s, T_odom_base)); });
      odometry.Pop();
    }
  };
  auto odometry_ended = [&] { return odometry.closed() && odometry.Front(Duration()) == nullptr; };

  while (!ShouldStop()) {
    ScanSlot* scan = scans.Front(kWait);
    if (scan == nullptr) {
      drain_odometry(lockstep() ? -inf : inf);
      if (scans.closed()) break;  // the LiDAR input ended (or failed)
      // A LiDAR that stalls must not hold an owed exchange (its marginals done meanwhile) or a
      // peer's resync: tried again every kWait.
      if (exchange_owed || publish_now.exchange(false)) exchange_owed = !Exchange();
      continue;
    }
    const double needed_s = scan->end_s + kOdometryMargin_s;
    drain_odometry(lockstep() ? needed_s + 0.05 : inf);
    if (reanchor_odometry && !T_odom_fix) {
      const Relocalising r = RelocaliseOn(*scan);
      if (r == Relocalising::kWait &&
          platform::SteadyNow() - scan->last_packet < kOdometryPatience) {
        static_cast<void>(odometry.Front(kWait));
        continue;
      }
      if (r != Relocalising::kDone) {  // older than the new odometry, or it never came
        scans.Pop();
        continue;
      }
      ReleaseNewOdometry();
    }
    if (mapper.odometry().newest_stamp() < needed_s && !odometry_ended()) {
      // A scan older than every odometry sample kept will never be covered: no use waiting.
      const auto start_pose = mapper.odometry().At(scan->start_s);
      const bool hopeless =
          mapper.odometry().size() > 0 && !start_pose && start_pose.error().code == Errc::kNotFound;
      const bool patient = !hopeless && (lockstep() || platform::SteadyNow() - scan->last_packet <
                                                           kOdometryPatience);
      if (patient) {
        static_cast<void>(odometry.Front(kWait));
        continue;
      }
      // Live: the odometry is late; the mapper skips the scan and counts it (kNoOdometry).
    }
    state = link::NodeState::kMapping;
    const SteadyTime t0 = platform::SteadyNow();
    core::LidarScanView view{scan->points, scan->time_offset_s, scan->start_s, scan->end_s};
    auto outcome = mapper.AddScan(view);
    const double end_s = scan->end_s;
    if (outcome && *outcome == core::ScanOutcome::kKeyframe) {
      const double took_ms = (platform::SteadyNow() - t0).seconds() * 1e3;
      keyframe_ms.Add(took_ms);
      solver.Offer(mapper.background_solve());  // a full solve begun at this keyframe
      // Only keyframes change the mapper's graph: only they are journaled, each with the motion
      // the sweeps before it tracked (replay makes the same keyframe from it).
      const core::LocalMapper::KeyframeMotion& motion = mapper.last_keyframe_motion();
      Journal([&](JournalWriter& j) {
        return static_cast<bool>(j.Motion(view.end_s, motion.T_last_new, motion.tracked)) &&
               static_cast<bool>(j.Scan(view.points_lidar, view.time_offset_s, view.start_s,
                                        view.end_s, config.mapper.max_range_m));
      });
      // After the keyframe's records: a snapshot the mapper took at its end begins the next
      // generation's journal here.
      if (checkpoint && checkpoint->AfterKeyframe(mapper, view.end_s)) {
        snapshot_keyframe_ms.Add(took_ms);
        std::lock_guard<std::mutex> lock(status_mutex);
        slam_status.snapshot_keyframe_p50_ms = snapshot_keyframe_ms.Percentile(0.5);
        slam_status.snapshot_keyframe_max_ms = snapshot_keyframe_ms.Percentile(1.0);
        slam_status.snapshot_keyframes = snapshot_keyframe_ms.count();
      }
      if (unpublished_keyframes.size() < unpublished_keyframes.capacity())
        unpublished_keyframes.push_back(scan->last_packet);
    }
    scans.Pop();
    {
      std::lock_guard<std::mutex> lock(status_mutex);
      const auto& s = mapper.stats();
      slam_status.scans = s.scans;
      slam_status.keyframes = s.keyframes;
      slam_status.no_odometry = s.no_odometry;
      slam_status.keyframe_p50_ms = keyframe_ms.Percentile(0.5);
      slam_status.keyframe_p99_ms = keyframe_ms.Percentile(0.99);
    }
    if (checkpoint && platform::SteadyNow() >= next_sync) {
      checkpoint->Sync();
      next_sync = platform::SteadyNow() + Duration::FromSeconds(config.checkpoint_sync_s);
    }
    if (next_exchange_s < 0) next_exchange_s = end_s + config.exchange_period_s;
    if (end_s >= next_exchange_s || exchange_owed || publish_now.exchange(false)) {
      exchange_owed = !Exchange();  // not taken yet: again after the next scan
      while (next_exchange_s <= end_s) next_exchange_s += config.exchange_period_s;
    }
  }
  if (ShouldStop()) return;

  // The recording ended: a final full solve, then keep serving the fleet.
  static_cast<void>(mapper.Finish());
  Journal([](JournalWriter& j) { return static_cast<bool>(j.Finish()); });
  if (checkpoint) checkpoint->Sync(/*final=*/true);
  state = link::NodeState::kInputDone;
  exchange_owed = !Exchange();
  const Duration period = Duration::FromSeconds(std::min(config.exchange_period_s, 1.0));
  // Owed exchanges are tried again every 20 ms: the collab thread takes one between its rounds.
  while (!ShouldStop()) {
    {
      std::unique_lock<std::mutex> lock(wake_mutex);
      wake_slam.wait_for(lock,
                         std::chrono::nanoseconds(exchange_owed ? kWait.nanoseconds() : period.nanoseconds()),
                         [&] { return publish_now.load() || ShouldStop(); });
    }
    publish_now = false;
    if (ShouldStop()) break;
    exchange_owed = !Exchange();
  }
}

}  // namespace msgraphs::runtime
