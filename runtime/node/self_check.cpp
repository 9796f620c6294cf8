// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cstdio>
#include <vector>

#include "build_info.hpp"
#include "modes.hpp"
#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/realtime.hpp"
#include "msgraphs/runtime/link/heartbeat_link.hpp"

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
  link::DdsSettings settings;
  settings.domain_id = domain_id;
  settings.loopback_only = true;

  const SteadyTime t_start = platform::SteadyNow();
  auto a = link::HeartbeatLink::Create(RobotId{1}, settings, BuildLabel());
  auto b = link::HeartbeatLink::Create(RobotId{2}, settings, BuildLabel());
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
  std::printf("  discovery           %.1f ms (both writers matched)\n", discovery.seconds() * 1e3);

  constexpr int kMessages = 50;
  std::vector<double> latency_us;
  int lost = 0;
  for (int i = 0; i < kMessages; ++i) {
    if (Status s = (*a)->Publish(platform::UnixNow(), platform::SteadyNow() - t_start); !s) {
      std::printf("  FAILED: publish: %s\n", s.error().detail);
      return 1;
    }
    auto got = (*b)->Receive(Duration::FromMilliseconds(1000));
    if (!got) {
      ++lost;
      continue;
    }
    latency_us.push_back(static_cast<double>((platform::UnixNow() - got->stamp).nanoseconds()) * 1e-3);
  }
  std::printf("  heartbeats robot 1 -> robot 2: %d sent, %zu received, %d lost\n", kMessages,
              latency_us.size(), lost);
  std::printf("  latency             p50 %.0f us, p95 %.0f us, max %.0f us\n",
              Percentile(latency_us, 0.5), Percentile(latency_us, 0.95), Percentile(latency_us, 1.0));
  if (lost != 0) {
    std::printf("self-check FAILED: heartbeats lost on a reliable loopback link\n");
    return 1;
  }
  std::printf("self-check passed\n");
  return 0;
}

}  // namespace msgraphs::runtime
