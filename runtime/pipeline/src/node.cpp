// SPDX-License-Identifier: MIT
// Node construction and the supervisor: telemetry, status lines, the status LED and the exit
// conditions, on the caller's thread.
#include <cinttypes>
#include <cstdio>

#include "msgraphs/drivers/gpio/gpio.hpp"
#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/realtime.hpp"
#include "msgraphs/runtime/pipeline/sweep_copy.hpp"
#include "node_impl.hpp"

namespace msgraphs::runtime {

namespace {

constexpr Duration kSupervisorTick =
    Duration::FromMilliseconds(50);  // the LED's blink needs ~10 Hz

const char* PaceName(const config::NodeConfig& c) {
  if (c.lidar_source == config::LidarSource::kUdp) return "live";
  return c.pace == config::Pace::kLockstep ? "recorded, lock-step" : "recorded pace";
}

// Discards what the session would send while it decides on the restored evidence.
class NullOutbox final : public core::CollabOutbox {
 public:
  void Send(core::CollabMessageType, std::uint16_t, std::span<const std::uint8_t>) override {}
};

}  // namespace

Node::Node(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Node::~Node() {
  if (!impl_) return;
  impl_->stopping = true;
  impl_->scans.Close();
  impl_->odometry.Close();
  impl_->wake_slam.notify_all();
  if (impl_->checkpoint) impl_->checkpoint->Wake();
  for (std::thread& t : impl_->threads)
    if (t.joinable()) t.join();
}

std::unique_ptr<Node> Node::Create(const config::NodeConfig& config,
                                   const std::string& build_label,
                                   std::string& error) {
  auto impl = std::make_unique<Impl>(config);
  Impl& m = *impl;
  m.build_label = build_label;
  m.started = platform::SteadyNow();
  auto fail = [&](const char* stage, const Error& e) {
    error = std::string(stage) + ": " + ToString(e.code) + ": " + e.detail;
    return nullptr;
  };

  // Every buffer is allocated here, before the threads start.
  for (std::size_t i = 0; i < config.scan_queue; ++i) {
    ScanSlot* slot = m.scans.BeginPush(Duration(), false);
    // Every point a sweep can carry, so the LiDAR thread's copy never grows a slot.
    const std::size_t capacity =
        SweepCapacity(drivers::velodyne::ScanAssemblerConfig{}, config.mapper.max_scan_points);
    slot->points.reserve(capacity);
    slot->time_offset_s.reserve(capacity);
    m.scans.CommitPush();
  }
  for (std::size_t i = 0; i < config.scan_queue; ++i) m.scans.Pop();
  if (Status s = m.mapper.Init(config.mapper); !s) return fail("local mapper", s.error());
  if (Status s = m.session.Init(config.collab, config.mapper.graph, -config.mapper.base_height_m);
      !s)
    return fail("collab session", s.error());
  if (Status s = m.publisher.Init(config.collab, config.mapper.graph, -config.mapper.base_height_m);
      !s)
    return fail("collab publisher", s.error());
  for (Impl::ExchangeSlot& slot : m.exchanges.slots()) {
    if (Status s = slot.x.Init(config.collab); !s) return fail("collab exchange", s.error());
    slot.keyframes.reserve(4096);
  }
  m.requests_mailbox.Init(config.collab.places.max_requests_queued);
  m.priors_mailbox.resize(config.mapper.max_plane_priors);
  m.priors_scratch.resize(config.mapper.max_plane_priors);
  m.priors_scratch_collab.resize(config.mapper.max_plane_priors);
  m.merge_log.reserve(Impl::kMaxMergeLog);
  m.merge_log_scratch.resize(64);
  m.unpublished_keyframes.reserve(4096);
  if (config.pace == config::Pace::kRecorded)
    m.replay_clock = std::make_unique<ReplayClock>(config.speed);

  if (!config.checkpoint_dir.empty()) {
    CheckpointSettings settings;
    settings.dir = config.checkpoint_dir;
    settings.robot = config.robot.value;
    settings.mapper_settings_crc = config.mapper_settings_crc;
    settings.snapshot_every_keyframes = config.snapshot_every_keyframes;
    CheckpointRestore restored;
    auto checkpoint = Checkpoint::Open(settings, m.mapper, m.session, restored);
    if (!checkpoint) return fail("checkpoint", checkpoint.error());
    m.checkpoint = std::move(*checkpoint);
    for (const std::string& why : restored.set_aside)
      std::printf("checkpoint: WARNING: set aside %s\n", why.c_str());
    if (restored.anything()) {
      NullOutbox discard;
      m.session.Match(discard);
      const JournalReplay& r = restored.replayed;
      std::printf(
          "resumed from checkpoint %s: %s%llu keyframes, %llu odometry samples, %llu peer messages, "
          "%llu prior updates replayed from %zu journal(s) in %.1f s (snapshot loaded in %.1f s)%s%s\n",
          config.checkpoint_dir.c_str(),
          restored.from_snapshot
              ? ("snapshot " + std::to_string(restored.snapshot_generation) + " (" +
                 std::to_string(m.mapper.stats().keyframes - r.scans) + " keyframes, " +
                 std::to_string(restored.session_messages) + " peer messages) + ")
                    .c_str()
              : "",
          static_cast<unsigned long long>(r.scans), static_cast<unsigned long long>(r.odometry),
          static_cast<unsigned long long>(r.messages), static_cast<unsigned long long>(r.priors),
          restored.journals, restored.replay_s, restored.load_s,
          r.stopped.empty() ? "" : "; stopped early: ", r.stopped.c_str());
      m.resume_scans_after_s = restored.last_scan_end_s;
      m.resume_odometry_after_s = restored.last_odometry_s;
      // Live odometry restarts its integration at identity, and the robot may have walked on
      // while the node was down: the SLAM thread relocalises the first scan against the map.
      if (config.odometry_source != config::OdometrySource::kCandump) {
        m.reanchor_odometry = true;
        m.T_old_last = restored.T_odom_last;
        m.old_last_stamp_s = restored.last_odometry_s;
        m.new_odometry.Init(config.mapper.odometry_capacity, config.mapper.odometry_max_gap_s);
      }
      std::lock_guard<std::mutex> lock(m.status_mutex);
      m.slam_status.keyframes = m.mapper.stats().keyframes;
    }
  }

  auto link = link::FleetLink::Create(config.robot, config.link);
  if (!link) return fail("DDS link", link.error());
  m.link = std::move(*link);
  if (config.ros_enabled) {
    auto ros = link::RosPublisher::Create(*m.link, "robot" + std::to_string(config.robot.value));
    if (!ros) return fail("ROS 2 topics", ros.error());
    m.ros = std::move(*ros);
  }

  if (!config.led_chip.empty()) {
    m.gpio = drivers::gpio::MakeLibgpiodProvider();
    drivers::gpio::GpioLineSpec spec;
    spec.chip = config.led_chip;
    spec.line = config.led_line;
    spec.active_low = config.led_active_low;
    auto line = m.gpio->OpenOutput(spec, "msgraphs_node", false);
    if (line) {
      m.led_line = std::move(*line);
      m.led = std::make_unique<drivers::gpio::StatusLed>(*m.led_line);
    } else {
      // A missing LED must not keep the robot from mapping.
      std::fprintf(stderr,
                   "msgraphs_node: WARNING: status LED %s line %s: %s; running without it\n",
                   config.led_chip.c_str(), config.led_line.c_str(), line.error().detail);
    }
  }
  return std::unique_ptr<Node>(new Node(std::move(impl)));
}

link::Telemetry Node::Impl::MakeTelemetry() const {
  link::Telemetry t;
  t.stamp = platform::UnixNow();
  t.uptime = platform::SteadyNow() - started;
  t.build = build_label;
  t.state = stopping ? link::NodeState::kStopping : state.load();
  {
    std::lock_guard<std::mutex> lock(status_mutex);
    t.keyframes = static_cast<std::uint32_t>(slam_status.keyframes);
    t.walls = slam_status.walls;
    t.rooms = slam_status.rooms;
    t.graph_version = slam_status.graph_version;
    for (std::size_t i = 0; i < slam_status.peer_count && !t.merged.full(); ++i)
      if (slam_status.peer_lines[i].merged) t.merged.push_back(slam_status.peer_lines[i].robot);
  }
  const link::LinkStats stats = link->stats();
  for (const link::TopicStats& s : stats.topics) {
    t.bytes_sent += s.sent_bytes;
    t.bytes_received += s.received_bytes;
  }
  {
    std::lock_guard<std::mutex> lock(resync_mutex);
    for (std::uint16_t r : resync_from)
      if (!t.resync_from.full()) t.resync_from.push_back(r);
  }
  return t;
}

void Node::Impl::PrintStatus(double since_start_s) {
  std::uint64_t& last_scans = status_last_scans;
  std::uint64_t& last_odometry = status_last_odometry;
  double& last_t = status_last_t;
  const double dt = std::max(since_start_s - last_t, 1e-3);
  const std::uint64_t scans_now = lidar_counters.items.load(),
                      odometry_now = odometry_counters.items.load();
  const auto sq = scans.stats(), oq = odometry.stats();
  SlamStatus s;
  {
    std::lock_guard<std::mutex> lock(status_mutex);
    s = slam_status;
  }
  const link::LinkStats ls = link->stats();
  std::uint64_t sent = 0, rejected = 0;
  for (const link::TopicStats& t : ls.topics) {
    sent += t.sent_bytes;
    rejected += t.rejected_version + t.rejected_sender + t.rejected_oversize + t.undecodable;
  }
  std::string peers;
  const std::uint64_t malformed = s.malformed;
  for (std::size_t i = 0; i < s.peer_count; ++i) {
    const SlamStatus::PeerLine& p = s.peer_lines[i];
    char buffer[96];
    std::snprintf(buffer, sizeof buffer, "%s r%u %s %.1f kB in", peers.empty() ? "" : ",", p.robot,
                  p.merged ? "merged" : "not merged", static_cast<double>(p.bytes_in) / 1e3);
    peers += buffer;
  }
  // Points cut from sweeps are shown only when there are any (a sensor beyond the assembler's
  // capacity), so the usual line stays as parsers know it.
  char cut_text[40] = "";
  if (const std::uint64_t cut = lidar_counters.points_cut.load(); cut > 0)
    std::snprintf(cut_text, sizeof cut_text, ", %" PRIu64 " points cut", cut);
  std::printf(
      "[robot %u %7.1f s %-10s] lidar %.1f Hz (queue peak %zu/%zu, dropped %" PRIu64
      ", bad %" PRIu64 "%s) | odometry %.0f Hz (peak %zu/%zu, dropped %" PRIu64 ", bad %" PRIu64
      ") | map %" PRIu64
      " keyframes (p50 %.0f ms, p99 %.0f ms), %u walls, %u rooms, %zu priors | link sent %.1f kB, "
      "rejected %" PRIu64 ", malformed %" PRIu64 "; peers:%s\n",
      config.robot.value, since_start_s, link::ToString(state.load()),
      static_cast<double>(scans_now - last_scans) / dt, sq.peak, sq.capacity, sq.dropped,
      lidar_counters.rejected.load(), cut_text, static_cast<double>(odometry_now - last_odometry) / dt,
      oq.peak, oq.capacity, oq.dropped, odometry_counters.rejected.load(), s.keyframes,
      s.keyframe_p50_ms, s.keyframe_p99_ms, s.walls, s.rooms, s.plane_priors,
      static_cast<double>(sent) / 1e3, rejected, malformed,
      peers.empty() ? " none yet" : peers.c_str());
  std::fflush(stdout);
  last_scans = scans_now;
  last_odometry = odometry_now;
  last_t = since_start_s;
}

int Node::Run(const std::atomic<bool>& stop) {
  Impl& m = *impl_;
  m.stop = &stop;
  const config::NodeConfig& c = m.config;
  std::printf("%s\n  robot %u (%s): lidar %s, odometry %s, %s\n", m.build_label.c_str(),
              c.robot.value, c.name.c_str(),
              c.lidar_source == config::LidarSource::kPcap ? c.pcap_path.c_str() : "Velodyne UDP",
              c.odometry_source == config::OdometrySource::kCandump ? c.candump_path.c_str()
              : c.odometry_source == config::OdometrySource::kUdp
                  ? ("CAN over UDP port " + std::to_string(c.can_udp_port)).c_str()
                  : ("SocketCAN " + c.can_interface).c_str(),
              PaceName(c));
  std::printf("  DDS domain %u%s, discovery %s, radio cap %s, exchange every %.1f s\n",
              c.link.dds.domain_id, c.link.dds.loopback_only ? " (127.0.0.1 only)" : "",
              c.link.dds.discovery == link::Discovery::kMulticast ? "multicast"
              : c.link.dds.discovery == link::Discovery::kUnicast ? "unicast peers"
                                                                  : "Discovery Server",
              c.link.max_bytes_per_s == 0
                  ? "none"
                  : (std::to_string(c.link.max_bytes_per_s / 1000) + " kB/s").c_str(),
              c.exchange_period_s);
  if (c.lock_memory) {
    if (Status s = platform::LockProcessMemory(); s)
      std::printf("  memory locked (mlockall)\n");
    else
      std::printf("  WARNING: memory NOT locked (%s): page faults may stall the sensor threads\n",
                  s.error().detail);
  }
  if (c.realtime_priority > 0) {
    const platform::RealtimeCapabilities caps = platform::ProbeRealtimeCapabilities();
    if (caps.can_use_fifo)
      std::printf("  sensor threads SCHED_FIFO priority %d\n", c.realtime_priority);
    else
      std::printf(
          "  WARNING: SCHED_FIFO not permitted (needs CAP_SYS_NICE or an rtprio limit): "
          "sensor threads run at normal priority\n");
  }
  std::fflush(stdout);

  m.threads.emplace_back([&m] { m.LidarLoop(); });
  m.threads.emplace_back([&m] { m.OdometryLoop(); });
  m.threads.emplace_back([&m] { m.SlamLoop(); });
  m.threads.emplace_back([&m] { m.CollabLoop(); });
  m.threads.emplace_back([&m] { m.solver.Loop([&m] { return m.ShouldStop(); }); });
  m.threads.emplace_back([&m] { m.marginals_solver.Loop([&m] { return m.ShouldStop(); }); });
  if (m.checkpoint)
    m.threads.emplace_back([&m] { m.checkpoint->RunWriter([&m] { return m.ShouldStop(); }); });

  int exit_code = 0;
  const Duration telemetry_period = Duration::FromSeconds(1.0 / c.telemetry_hz);
  const Duration status_period = Duration::FromSeconds(c.status_period_s);
  SteadyTime next_telemetry = m.started, next_status = m.started + status_period;
  std::uint64_t seen_changes = 0, seen_drops = 0;
  SteadyTime last_change = m.started, done_since;
  bool done_seen = false;
  if (m.led) m.led->SetHealth(drivers::gpio::Health::kStarting, m.started);
  while (!stop.load()) {
    platform::SleepUntil(platform::SteadyNow() + kSupervisorTick);
    const SteadyTime now = platform::SteadyNow();
    if (m.lidar_counters.failed || m.odometry_counters.failed) {
      InputCounters& failed = m.lidar_counters.failed ? m.lidar_counters : m.odometry_counters;
      std::lock_guard<std::mutex> lock(failed.error_mutex);
      std::fprintf(stderr, "msgraphs_node: input failed: %s\n", failed.error.c_str());
      if (m.led) m.led->SetHealth(drivers::gpio::Health::kFault, now);
      exit_code = 1;
      break;
    }
    if (now >= next_telemetry) {
      static_cast<void>(m.link->PublishTelemetry(m.MakeTelemetry()));
      next_telemetry = next_telemetry + telemetry_period;
      if (next_telemetry < now) next_telemetry = now + telemetry_period;
    }
    const std::uint64_t drops = m.scans.stats().dropped + m.odometry.stats().dropped;
    if (m.led) {
      using drivers::gpio::Health;
      const Health health = m.state.load() == link::NodeState::kStarting ? Health::kStarting
                            : drops != seen_drops                        ? Health::kDegraded
                                                                         : Health::kOk;
      if (health != m.led->health()) m.led->SetHealth(health, now);
      m.led->Update(now);
    }
    if (now >= next_status) {
      m.PrintStatus((now - m.started).seconds());
      next_status = next_status + status_period;
      seen_drops = drops;  // the LED shows degraded for one status period after a drop
    }
    if (c.max_run_s > 0 && (now - m.started).seconds() >= c.max_run_s) {
      std::printf("robot %u: max_run_s reached\n", c.robot.value);
      break;
    }
    // Exit once the recordings of this robot and of every robot heard have ended and nothing
    // changed in the collaborative estimate for exit_after_done_s.
    const std::uint64_t changes = m.collab_changes.load();
    if (changes != seen_changes) {
      seen_changes = changes;
      last_change = now;
    }
    if (c.exit_after_done_s > 0 && m.state.load() == link::NodeState::kInputDone) {
      if (!done_seen) {
        done_seen = true;
        done_since = now;
      }
      bool peers_done = true;
      for (const auto& peer : m.link->Peers()) {
        if (peer.alive && peer.telemetry.state != link::NodeState::kInputDone &&
            peer.telemetry.state != link::NodeState::kStopping)
          peers_done = false;
      }
      const Duration quiet = Duration::FromSeconds(c.exit_after_done_s);
      if (peers_done && now - last_change >= quiet && now - done_since >= quiet) break;
    }
  }
  m.stopping = true;
  static_cast<void>(m.link->PublishTelemetry(m.MakeTelemetry()));  // state: stopping
  m.scans.Close();
  m.odometry.Close();
  m.wake_slam.notify_all();
  for (std::thread& t : m.threads) t.join();
  m.threads.clear();
  // The last exchange the SLAM thread posted (after its final solve) goes out and into the
  // outputs: the collab thread may have stopped before taking it.
  m.IngestExchange();
  if (m.led) m.led->SetHealth(drivers::gpio::Health::kOff, platform::SteadyNow());
  m.PrintStatus((platform::SteadyNow() - m.started).seconds());
  m.WriteOutputs();
  m.WriteExports();
  m.PrintReport();
  return exit_code;
}

}  // namespace msgraphs::runtime
