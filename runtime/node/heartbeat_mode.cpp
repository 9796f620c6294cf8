// SPDX-License-Identifier: MIT
#include <algorithm>
#include <cstdio>
#include <set>

#include "modes.hpp"
#include "msgraphs/platform/clock.hpp"
#include "msgraphs/runtime/link/fleet_link.hpp"

namespace msgraphs::runtime {

int RunHeartbeatMode(const HeartbeatModeOptions& options) {
  PrintBanner(options.robot_id);
  link::LinkSettings settings;
  settings.dds = options.dds;
  if (Status valid = settings.Validate(); !valid) {
    std::fprintf(stderr, "msgraphs_node: %s\n", valid.error().detail);
    return 2;
  }
  auto link = link::FleetLink::Create(options.robot_id, settings);
  if (!link) {
    std::fprintf(stderr, "msgraphs_node: DDS link: %s: %s\n", ToString(link.error().code),
                 link.error().detail);
    return 1;
  }
  const SteadyTime t_start = platform::SteadyNow();
  const SteadyTime t_end = t_start + Duration::FromSeconds(options.duration_s);
  const Duration period = Duration::FromSeconds(1.0 / options.rate_hz);
  // Once every expected peer was heard, keep publishing a little longer so that the peers
  // hear us too before this process leaves the network.
  const Duration linger = Duration::FromMilliseconds(1000);
  std::set<std::uint16_t> heard;
  SteadyTime done_at = t_end;
  while (platform::SteadyNow() < done_at) {
    link::Telemetry t;
    t.stamp = platform::UnixNow();
    t.uptime = platform::SteadyNow() - t_start;
    t.build = BuildLabel();
    static_cast<void>((*link)->PublishTelemetry(t));
    platform::SleepUntil(std::min(done_at, platform::SteadyNow() + period));
    for (const auto& peer : (*link)->Peers()) {
      if (!peer.has_telemetry) continue;  // discovered, not heard yet
      if (!heard.insert(peer.telemetry.robot.value).second) continue;
      std::printf("robot %u: heard robot %u (%s) after %.0f ms\n", options.robot_id.value,
                  peer.telemetry.robot.value, peer.telemetry.build.c_str(),
                  (platform::SteadyNow() - t_start).seconds() * 1e3);
      std::fflush(stdout);
      if (options.expect_peers > 0 && static_cast<int>(heard.size()) >= options.expect_peers)
        done_at = std::min(t_end, platform::SteadyNow() + linger);
    }
  }
  const link::TopicStats stats = (*link)->stats().topics.back();
  std::printf("robot %u: sent %llu, received %llu, rejected %llu, peers heard %zu\n",
              options.robot_id.value, static_cast<unsigned long long>(stats.sent),
              static_cast<unsigned long long>(stats.received),
              static_cast<unsigned long long>(stats.rejected_version + stats.rejected_sender),
              heard.size());
  if (options.expect_peers > 0 && static_cast<int>(heard.size()) < options.expect_peers) {
    std::fprintf(stderr, "msgraphs_node: heard %zu of %d expected peers within %.1f s\n",
                 heard.size(), options.expect_peers, options.duration_s);
    return 3;
  }
  return 0;
}

}  // namespace msgraphs::runtime
