// SPDX-License-Identifier: MIT
// The two input threads: LiDAR (Velodyne UDP or pcap) and encoder odometry (SocketCAN or
// candump). Each fills its queue in place; recorded inputs follow the replay pace.
#include <cstdio>
#include <optional>

#include "msgraphs/base/ipv4.hpp"
#include "msgraphs/drivers/can_odometry/candump.hpp"
#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/can_odometry/odometry_stream.hpp"
#include "msgraphs/drivers/can_odometry/socketcan.hpp"
#include "msgraphs/drivers/velodyne/recorded_scans.hpp"
#include "msgraphs/drivers/velodyne/velodyne_source.hpp"
#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/realtime.hpp"
#include "msgraphs/platform/udp_socket.hpp"
#include "msgraphs/runtime/pipeline/sweep_copy.hpp"
#include "node_impl.hpp"

namespace msgraphs::runtime {

namespace {

constexpr Duration kPollSlice = Duration::FromMilliseconds(50);

void CopyScan(const drivers::velodyne::Scan& scan, ScanSlot& slot, InputCounters& counters) {
  const std::size_t cut = CopySweep(scan, slot.points, slot.time_offset_s);
  if (cut > 0) counters.points_cut.fetch_add(cut, std::memory_order_relaxed);
  slot.start_s = scan.start_time.seconds_since_epoch();
  slot.end_s = scan.end_time.seconds_since_epoch();
  slot.sequence = scan.sequence;
}

void SetUpThread(const char* name, int realtime_priority) {
  static_cast<void>(platform::SetCurrentThreadName(name));
  // Refusal was reported once in the banner; the thread then runs at normal priority.
  if (realtime_priority > 0)
    static_cast<void>(platform::SetCurrentThreadRealtime(realtime_priority));
}

}  // namespace

void Node::Impl::LidarLoop() {
  SetUpThread("msg-lidar", config.realtime_priority);
  // In lock-step the reader waits for room (nothing may be lost); otherwise a full queue drops
  // the newest scan and counts it, as a live sensor would.
  auto push = [&](auto&& fill) {
    for (;;) {
      if (ShouldStop()) return;
      ScanSlot* slot = scans.BeginPush(lockstep() ? kPollSlice : Duration(), !lockstep());
      if (slot == nullptr) {
        if (lockstep() && !scans.closed()) continue;
        return;
      }
      fill(*slot);
      scans.CommitPush();
      lidar_counters.items.fetch_add(1, std::memory_order_relaxed);
      return;
    }
  };

  if (config.lidar_source == config::LidarSource::kPcap) {
    auto recorded = drivers::velodyne::RecordedScans::Open(config.pcap_path);
    if (!recorded) {
      lidar_counters.Fail("cannot open the pcap " + config.pcap_path);
      scans.Close();
      return;
    }
    while (!ShouldStop()) {
      const drivers::velodyne::Scan* scan = recorded->Next();
      if (scan == nullptr) break;
      // Resumed from a checkpoint: what the map already holds is skipped, without pacing.
      if (scan->end_time.seconds_since_epoch() <= resume_scans_after_s) continue;
      if (!lockstep()) {
        const SteadyTime due =
            replay_clock->Due(scan->end_time.seconds_since_epoch(), platform::SteadyNow());
        while (!ShouldStop() && platform::SteadyNow() < due)
          platform::SleepUntil(std::min(due, platform::SteadyNow() + kPollSlice));
      }
      push([&](ScanSlot& slot) {
        CopyScan(*scan, slot, lidar_counters);
        slot.last_packet = platform::SteadyNow();
      });
    }
    lidar_counters.done = true;
    scans.Close();
    return;
  }

  drivers::velodyne::VelodyneSourceConfig source_config;
  auto bind = ParseIpv4Address(config.bind_address.c_str());
  if (bind) source_config.bind_address = *bind;
  source_config.data_port = config.data_port;
  source_config.position_port = config.position_port;
  if (!config.sensor_address.empty()) {
    if (auto sensor = ParseIpv4Address(config.sensor_address.c_str()))
      source_config.sensor_address = *sensor;
  }
  auto source = drivers::velodyne::VelodyneSource::Open(source_config);
  if (!source) {
    lidar_counters.Fail(std::string("cannot open the Velodyne UDP ports: ") +
                        source.error().detail);
    scans.Close();
    return;
  }
  std::uint64_t malformed_seen = 0;
  while (!ShouldStop()) {
    auto got = source->Poll(platform::SteadyNow() + kPollSlice);
    const auto stats = source->stats();
    if (stats.malformed_data != malformed_seen) {
      lidar_counters.rejected.fetch_add(stats.malformed_data - malformed_seen,
                                        std::memory_order_relaxed);
      malformed_seen = stats.malformed_data;
    }
    if (!got) {
      lidar_counters.Fail(std::string("Velodyne receive failed: ") + got.error().detail);
      break;
    }
    if (!*got || !source->scan().complete) continue;
    push([&](ScanSlot& slot) {
      CopyScan(source->scan(), slot, lidar_counters);
      slot.last_packet = platform::SteadyNow();
    });
  }
  scans.Close();
}

void Node::Impl::OdometryLoop() {
  SetUpThread("msg-odom", config.realtime_priority);
  auto stream = drivers::can_odometry::OdometryStream::Create({});
  if (!stream) {
    odometry_counters.Fail(std::string("odometry integrator: ") + stream.error().detail);
    odometry.Close();
    return;
  }
  std::uint64_t rejected_seen = 0;
  // One CAN frame; a complete odometry sample goes into the queue.
  auto add = [&](const drivers::can_odometry::CanFrame& frame, UnixTime stamp) {
    const bool sample = stream->Add(frame, stamp);
    const auto s = stream->stats();
    const std::uint64_t rejected = s.crc_errors + s.bad_frames + s.foreign_ids + s.rejected_samples;
    if (rejected != rejected_seen) {
      odometry_counters.rejected.fetch_add(rejected - rejected_seen, std::memory_order_relaxed);
      rejected_seen = rejected;
    }
    if (!sample) return;
    for (;;) {
      if (ShouldStop()) return;
      OdometrySlot* slot = odometry.BeginPush(lockstep() ? kPollSlice : Duration(), !lockstep());
      if (slot == nullptr) {
        if (lockstep() && !odometry.closed()) continue;
        return;
      }
      const auto& p = stream->pose();
      const auto& P = p.T_odom_base;
      slot->stamp_s = p.stamp.seconds_since_epoch();
      slot->T_odom_base.linear() =
          Eigen::Quaterniond(P.qw, P.qx, P.qy, P.qz).normalized().toRotationMatrix();
      slot->T_odom_base.translation() = Eigen::Vector3d(P.x_m, P.y_m, P.z_m);
      odometry.CommitPush();
      odometry_counters.items.fetch_add(1, std::memory_order_relaxed);
      return;
    }
  };

  if (config.odometry_source == config::OdometrySource::kCandump) {
    auto reader = drivers::can_odometry::CandumpFileReader::Open(config.candump_path.c_str());
    if (!reader) {
      odometry_counters.Fail("cannot open the candump log " + config.candump_path);
      odometry.Close();
      return;
    }
    drivers::can_odometry::CandumpLine line;
    while (!ShouldStop()) {
      auto next = reader->Next(line);
      if (!next) {
        odometry_counters.Fail(std::string("candump read failed: ") + next.error().detail);
        break;
      }
      if (!*next) {
        odometry_counters.done = true;
        break;
      }
      // Resumed: the integrator still sees every frame (it integrates them), the queue only
      // the samples after the checkpoint's last.
      if (line.stamp.seconds_since_epoch() <= resume_odometry_after_s) {
        static_cast<void>(stream->Add(line.frame, line.stamp));
        continue;
      }
      if (!lockstep()) {
        const SteadyTime due =
            replay_clock->Due(line.stamp.seconds_since_epoch(), platform::SteadyNow());
        while (!ShouldStop() && platform::SteadyNow() < due)
          platform::SleepUntil(std::min(due, platform::SteadyNow() + kPollSlice));
      }
      add(line.frame, line.stamp);
    }
    odometry_counters.rejected.fetch_add(reader->stats().malformed, std::memory_order_relaxed);
    odometry.Close();
    return;
  }

  if (config.odometry_source == config::OdometrySource::kUdp) {
    // One candump line per datagram; the line's own stamp is the recording's: arrival counts.
    platform::UdpReceiverConfig udp_config;
    if (auto bind = ParseIpv4Address(config.bind_address.c_str())) udp_config.bind.address = *bind;
    udp_config.bind.port = config.can_udp_port;
    udp_config.max_payload_bytes = drivers::can_odometry::kMaxCandumpLine;
    udp_config.receive_buffer_bytes = 1 << 20;
    auto udp = platform::UdpReceiver::Open(udp_config);
    if (!udp) {
      odometry_counters.Fail(std::string("cannot open the CAN-over-UDP port: ") +
                             udp.error().detail);
      odometry.Close();
      return;
    }
    while (!ShouldStop()) {
      auto n = udp->Receive(platform::SteadyNow() + kPollSlice);
      if (!n) {
        odometry_counters.Fail(std::string("CAN-over-UDP receive failed: ") + n.error().detail);
        break;
      }
      for (std::size_t i = 0; i < *n; ++i) {
        const platform::ReceivedDatagram& d = udp->datagram(i);
        auto line = drivers::can_odometry::ParseCandumpLine(
            {reinterpret_cast<const char*>(d.payload.data()), d.payload.size()});
        if (!line || line->kind != drivers::can_odometry::CandumpLine::Kind::kFrame) {
          odometry_counters.rejected.fetch_add(1, std::memory_order_relaxed);
          continue;
        }
        add(line->frame, d.kernel_time);
      }
    }
    odometry.Close();
    return;
  }

  auto can = drivers::can_odometry::SocketCanSource::Open(
      drivers::can_odometry::SocketCanConfig::Odometry(config.can_interface));
  if (!can) {
    odometry_counters.Fail("cannot open SocketCAN interface " + config.can_interface + ": " +
                           can.error().detail);
    odometry.Close();
    return;
  }
  while (!ShouldStop()) {
    auto n = can->Receive(platform::SteadyNow() + kPollSlice);
    if (!n) {
      odometry_counters.Fail(std::string("SocketCAN receive failed: ") + n.error().detail);
      break;
    }
    for (std::size_t i = 0; i < *n; ++i) add(can->frame(i).frame, can->frame(i).kernel_time);
  }
  odometry.Close();
}

}  // namespace msgraphs::runtime
