// SPDX-License-Identifier: MIT
#include <algorithm>
#include <array>
#include <cstdio>
#include <vector>

#include "build_info.hpp"
#include "modes.hpp"
#include "msgraphs/core/collab/place_messages.hpp"
#include "msgraphs/core/collab/room_messages.hpp"
#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/realtime.hpp"
#include "msgraphs/runtime/link/fleet_link.hpp"

namespace msgraphs::runtime {

std::string BuildLabel() {
  return std::string("msgraphs ") + kVersion + " (" + kGitCommit + ", " + kBuildType + ", " +
         kTargetProcessor + ")";
}

void PrintBanner(RobotId robot_id) {
  const platform::RealtimeCapabilities caps = platform::ProbeRealtimeCapabilities();
  std::printf("%s\n", BuildLabel().c_str());
  if (robot_id.valid()) std::printf("  robot id            %u\n", robot_id.value);
  std::printf("  monotonic clock     resolution %lld ns\n",
              static_cast<long long>(platform::SteadyResolution().nanoseconds()));
  std::printf("  SCHED_FIFO          %s (max priority %d)\n",
              caps.can_use_fifo ? "available" : "NOT permitted: threads run at normal priority",
              caps.max_fifo_priority);
  if (caps.memlock_limit_bytes < 0) {
    std::printf("  memory locking      %s, RLIMIT_MEMLOCK unlimited\n",
                caps.can_lock_memory ? "available" : "NOT permitted");
  } else {
    std::printf("  memory locking      %s, RLIMIT_MEMLOCK %lld KiB\n",
                caps.can_lock_memory ? "available" : "NOT permitted",
                static_cast<long long>(caps.memlock_limit_bytes / 1024));
  }
}

namespace {

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto idx = static_cast<std::size_t>(p * static_cast<double>(values.size() - 1) + 0.5);
  return values[idx];
}

}  // namespace

int RunSelfCheck(std::uint32_t domain_id) {
  PrintBanner(RobotId{});
  std::printf("\nself-check: Fast DDS exchange between two participants on 127.0.0.1 (domain %u)\n",
              domain_id);
  // Through the UDP stack on 127.0.0.1, as between two robots' processes, not in memory.
  link::DisableIntraprocessDelivery();
  link::LinkSettings settings;
  settings.dds.domain_id = domain_id;
  settings.dds.loopback_only = true;

  const SteadyTime t_start = platform::SteadyNow();
  auto a = link::FleetLink::Create(RobotId{1}, settings);
  auto b = link::FleetLink::Create(RobotId{2}, settings);
  if (!a || !b) {
    const Error& e = !a ? a.error() : b.error();
    std::printf("  FAILED: %s: %s\n", ToString(e.code), e.detail);
    return 1;
  }
  // Matched: our own reader and the other participant's reader.
  const SteadyTime discovery_deadline = t_start + Duration::FromMilliseconds(5000);
  while (((*a)->matched_readers() < 2 || (*b)->matched_readers() < 2) &&
         platform::SteadyNow() < discovery_deadline) {
    platform::SleepUntil(platform::SteadyNow() + Duration::FromMilliseconds(1));
  }
  const Duration discovery = platform::SteadyNow() - t_start;
  if ((*a)->matched_readers() < 2 || (*b)->matched_readers() < 2) {
    std::printf("  FAILED: participants did not discover each other within 5 s\n");
    return 1;
  }
  std::printf("  discovery           %.1f ms (both telemetry writers matched)\n",
              discovery.seconds() * 1e3);

  // Room cloud requests robot 1 -> robot 2: the collab path, addressed, through every check.
  constexpr int kMessages = 50;
  std::vector<double> latency_us;
  int lost = 0;
  std::array<std::uint8_t, core::kRoomCloudRequestBytes> request{};
  link::InboundMessage received;
  for (int i = 0; i < kMessages; ++i) {
    static_cast<void>(
        core::EncodeRoomCloudRequest({1, 2, static_cast<std::uint32_t>(i), 1}, request));
    const SteadyTime sent = platform::SteadyNow();
    (*a)->Send(core::CollabMessageType::kRoomCloudRequest, 2, request);
    if (!(*b)->Receive(received, Duration::FromMilliseconds(1000)) ||
        received.bytes.size() != request.size() ||
        !std::equal(received.bytes.begin(), received.bytes.end(), request.begin())) {
      ++lost;
      continue;
    }
    latency_us.push_back((platform::SteadyNow() - sent).seconds() * 1e6);
  }
  std::printf("  room cloud requests robot 1 -> robot 2: %d sent, %zu received intact, %d lost\n",
              kMessages, latency_us.size(), lost);
  std::printf("  latency             p50 %.0f us, p95 %.0f us, max %.0f us\n",
              Percentile(latency_us, 0.5), Percentile(latency_us, 0.95),
              Percentile(latency_us, 1.0));
  if (lost != 0) {
    std::printf("self-check FAILED: messages lost on a reliable loopback link\n");
    return 1;
  }
  // The merge decision's fallback: a place request robot 1 -> robot 2 and the place cloud back,
  // on their own topics, intact and typed.
  std::array<std::uint8_t, core::kPlaceRequestBytes> place_request{};
  static_cast<void>(core::EncodePlaceRequest({1, 2, 1, {3.0f, -2.0f}, 5.0f}, place_request));
  const std::array<Eigen::Vector3f, 3> points = {Eigen::Vector3f(0.5f, 0.2f, 1.0f), Eigen::Vector3f(-4.0f, 2.0f, 0.3f),
                                                 Eigen::Vector3f(1.0f, -3.0f, 1.9f)};
  std::vector<std::uint8_t> place_cloud(core::PlaceCloudEncodedSize(points.size()));
  static_cast<void>(core::EncodePlaceCloud({2, 1, 1, {3.0f, -2.0f}, -0.5f, 0.04f}, points, place_cloud));
  auto round_trip = [&](link::FleetLink& from, link::FleetLink& to, core::CollabMessageType type, std::uint16_t addressee,
                        std::span<const std::uint8_t> bytes) {
    from.Send(type, addressee, bytes);
    return to.Receive(received, Duration::FromMilliseconds(1000)) && received.type == type &&
           std::equal(received.bytes.begin(), received.bytes.end(), bytes.begin(), bytes.end());
  };
  const bool place_ok = round_trip(**a, **b, core::CollabMessageType::kPlaceRequest, 2, place_request) &&
                        round_trip(**b, **a, core::CollabMessageType::kPlaceCloud, 1, place_cloud);
  std::printf("  place request robot 1 -> robot 2 and its cloud back: %s\n", place_ok ? "intact" : "LOST or altered");
  if (!place_ok) {
    std::printf("self-check FAILED: a place message was lost or altered on a reliable loopback link\n");
    return 1;
  }
  std::printf("self-check passed\n");
  return 0;
}

}  // namespace msgraphs::runtime
