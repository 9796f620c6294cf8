// SPDX-License-Identifier: MIT
// The collab thread: messages from the link into the session, the own map the SLAM thread
// prepared (the exchange) out through the session, room matching, and the two recovery paths
// of the link:
// - a robot we hear whose graph we lack or hold behind for a while (we joined late, a delta
//   was lost, the link was cut) is put on our resync list, which our telemetry carries;
// - a robot whose telemetry lists us gets everything again (ResendAll, published by the SLAM
//   thread at once).
#include <algorithm>
#include <map>

#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/realtime.hpp"
#include "node_impl.hpp"

namespace msgraphs::runtime {

namespace {

constexpr Duration kReceiveWait = Duration::FromMilliseconds(100);
constexpr std::size_t kMessagesPerRound = 64;  ///< then Match runs, even under a flood
/// A peer's graph held behind what its telemetry announces for this long: ask for all of it.
constexpr Duration kBehindPatience = Duration::FromSeconds(3.0);
/// At most one ResendAll per this interval, however many robots ask.
constexpr Duration kResendInterval = Duration::FromSeconds(2.0);

}  // namespace

void Node::Impl::PublishCollabStatus() {
  SlamStatus::PeerLine lines[SlamStatus::kPeerLines];
  std::size_t n = 0;
  for (std::size_t i = 0; i < session.peers() && n < SlamStatus::kPeerLines; ++i) {
    const core::CollabPeerStats p = session.peer_stats(i);
    std::uint64_t in = 0;
    for (std::uint64_t b : p.bytes_received) in += b;
    lines[n++] = {p.robot, p.merged, in};
  }
  std::lock_guard<std::mutex> lock(status_mutex);
  std::copy_n(lines, n, slam_status.peer_lines.begin());
  slam_status.peer_count = n;
  slam_status.malformed = session.stats().malformed;
}

void Node::Impl::IngestExchange() {
  ExchangeSlot* taken = exchanges.Take();
  if (taken == nullptr) return;
  ExchangeSlot& slot = *taken;
  std::uint32_t version = 0;
  {
    std::lock_guard<std::mutex> lock(session_mutex);
    static_cast<void>(session.Ingest(slot.x, slot.publisher, *link));
    version = session.distilled().version;
    RefreshRosFleet();
    PublishCollabStatus();
  }
  const SteadyTime now = platform::SteadyNow();
  {
    std::lock_guard<std::mutex> lock(status_mutex);
    for (const SteadyTime t : slot.keyframes) wire_ms.Add((now - t).seconds() * 1e3);
    slam_status.graph_version = version;
    slam_status.publishes += 1;
    slam_status.wire_p50_ms = wire_ms.Percentile(0.5);
    slam_status.wire_p99_ms = wire_ms.Percentile(0.99);
    slam_status.wire_max_ms = wire_ms.Percentile(1.0);
    slam_status.wire_samples = wire_ms.count();
  }
  exchanges.Release();
}

void Node::Impl::CollabLoop() {
  static_cast<void>(platform::SetCurrentThreadName("msg-collab"));
  link::InboundMessage message;
  message.bytes.reserve(
      link::kMaxPayloadBytes[static_cast<std::size_t>(core::CollabMessageType::kRoomCloud)]);
  std::map<std::uint16_t, SteadyTime> behind_since;
  std::map<std::uint16_t, std::uint64_t> gaps_seen;
  SteadyTime last_resend;
  bool resent_once = false;
  const Duration match_period = Duration::FromSeconds(config.match_period_s);
  SteadyTime next_match = platform::SteadyNow();
  bool pending_change = false;  // received since the last Match

  while (!ShouldStop()) {
    std::size_t received = 0;
    bool changed = false;
    if (link->Receive(message, kReceiveWait)) {
      std::lock_guard<std::mutex> lock(session_mutex);
      do {
        // Malformed messages are counted by the session (per peer) and dropped here.
        if (session.Receive(message.type, message.bytes, *link)) {
          changed = true;
          // Peers' graphs, descriptors and free space into the checkpoint; requests are
          // answered already and clouds are asked for again when needed.
          if (message.type == core::CollabMessageType::kDistilledGraph ||
              message.type == core::CollabMessageType::kRoomDescriptor ||
              message.type == core::CollabMessageType::kFreeSpace)
            Journal([&](JournalWriter& j) {
              return static_cast<bool>(j.Message(message.type, message.bytes));
            });
        }
        ++received;
      } while (received < kMessagesPerRound && link->Receive(message, Duration()));
      PublishCollabStatus();
    }
    // A snapshot the SLAM thread began: the session's peer state, under the session's lock.
    if (checkpoint && checkpoint->session_wanted()) {
      std::lock_guard<std::mutex> lock(session_mutex);
      checkpoint->CaptureSession(session);
    }
    // The own map the SLAM thread prepared, and peers' place requests for its next one.
    IngestExchange();
    {
      // Into the mailbox while it has room; the rest stay queued in the session.
      std::lock_guard<std::mutex> lock(session_mutex);
      std::lock_guard<std::mutex> requests_lock(requests_mutex);
      session.TakePlaceRequests(requests_mailbox);
    }
    pending_change = pending_change || changed;
    bool origins_changed = false;
    const SteadyTime before_match = platform::SteadyNow();
    // Match on a fixed period: its call count is the session's clock for request retries.
    if (before_match >= next_match) {
      next_match = before_match + match_period;
      std::lock_guard<std::mutex> lock(session_mutex);
      origins_changed = session.Match(*link, (before_match - started).seconds());
      // The decisions it logged, kept for merge_log.csv.
      for (std::size_t n = 0; (n = session.MergeLog(merge_log_sequence, merge_log_scratch)) > 0;) {
        for (std::size_t i = 0; i < n; ++i) {
          if (merge_log.size() < kMaxMergeLog)
            merge_log.push_back(merge_log_scratch[i]);
          else
            ++merge_log_dropped;
        }
        merge_log_sequence = merge_log_scratch[n - 1].sequence;
      }
      const double match_took_ms = (platform::SteadyNow() - before_match).seconds() * 1e3;
      match_ms.Add(match_took_ms);
      {
        std::lock_guard<std::mutex> status_lock(status_mutex);
        slam_status.match_p50_ms = match_ms.Percentile(0.5);
        slam_status.match_p99_ms = match_ms.Percentile(0.99);
        slam_status.match_max_ms = match_ms.Percentile(1.0);
      }
      changed = pending_change;
      pending_change = false;
      if (changed || origins_changed) RefreshRosFleet();
      PublishCollabStatus();
      if ((changed || origins_changed) && config.feedback) {
        // The priors are recomputed whenever a peer's walls or an origin moved; the SLAM
        // thread takes the newest at its next exchange.
        const std::size_t n = session.PlanePriors(std::span(priors_scratch_collab));
        std::lock_guard<std::mutex> priors_lock(priors_mutex);
        std::copy_n(priors_scratch_collab.begin(), n, priors_mailbox.begin());
        priors_count = n;
        ++priors_generation;
      }
    }
    if (changed || origins_changed) collab_changes.fetch_add(1, std::memory_order_relaxed);

    // Recovery, from what the other robots' telemetry says.
    const SteadyTime now = platform::SteadyNow();
    std::vector<std::uint16_t> want;
    bool asked_for_us = false;
    for (const link::FleetLink::PeerView& peer : link->Peers()) {
      const std::uint16_t robot = peer.telemetry.robot.value;
      if (!peer.alive || robot == 0) continue;
      for (std::uint16_t r : peer.telemetry.resync_from) asked_for_us |= r == config.robot.value;
      if (peer.telemetry.graph_version == 0) continue;
      std::uint32_t held = 0;
      std::uint64_t gaps = 0;
      {
        std::lock_guard<std::mutex> lock(session_mutex);
        for (std::size_t i = 0; i < session.peers(); ++i) {
          const core::CollabPeerStats s = session.peer_stats(i);
          if (s.robot != robot) continue;
          held = s.graph_version;
          gaps = s.graph_gaps;
        }
      }
      const bool gap = gaps != gaps_seen[robot];
      gaps_seen[robot] = gaps;
      if (held >= peer.telemetry.graph_version && !gap) {
        behind_since.erase(robot);
        continue;
      }
      auto [it, fresh] = behind_since.try_emplace(robot, now);
      if (gap || now - it->second >= kBehindPatience) want.push_back(robot);
    }
    {
      std::lock_guard<std::mutex> lock(resync_mutex);
      if (want != resync_from && !want.empty())
        resyncs_requested.fetch_add(1, std::memory_order_relaxed);
      resync_from = want;
    }
    if (asked_for_us && (!resent_once || now - last_resend >= kResendInterval)) {
      {
        std::lock_guard<std::mutex> lock(session_mutex);
        session.ResendAll();
      }
      resends.fetch_add(1, std::memory_order_relaxed);
      last_resend = now;
      resent_once = true;
      publish_now = true;
      wake_slam.notify_one();
    }
  }
}

}  // namespace msgraphs::runtime
