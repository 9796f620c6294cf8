// SPDX-License-Identifier: MIT
// Relates a device clock (a sensor's or a CAN bridge's) to the host clock from (device time,
// host arrival time) pairs. Arrival = device time + offset + latency, latency >= 0 and jittery,
// so the filter tracks the lower envelope of (arrival - device): a faster sample lowers it at
// once, and it may rise only at a bounded drift rate. Device spacing between samples is then
// kept exactly and host jitter is removed. A change beyond max_jump restarts the filter.
#pragma once

#include <cstdint>

#include "msgraphs/base/time.hpp"

namespace msgraphs {

class ClockOffsetFilter {
 public:
  struct Config {
    double max_drift_ppm = 200.0;  ///< crystal drift between two clocks is tens of ppm
    Duration max_jump = Duration::FromMilliseconds(500);
  };

  ClockOffsetFilter() = default;
  explicit ClockOffsetFilter(const Config& config) : config_(config) {}

  /// Feeds one pair; returns the host time of `device_ns`.
  std::int64_t Update(std::int64_t device_ns, std::int64_t arrival_ns) {
    const std::int64_t candidate = arrival_ns - device_ns;
    if (!initialised_) {
      offset_ns_ = candidate;
      initialised_ = true;
    } else {
      const std::int64_t diff = candidate - offset_ns_;
      const std::int64_t jump = config_.max_jump.nanoseconds();
      if (diff > jump || -diff > jump) {
        offset_ns_ = candidate;
        ++resets_;
      } else if (diff < 0) {
        offset_ns_ = candidate;
      } else {
        const std::int64_t elapsed_ns = device_ns - last_device_ns_;
        const auto allowance = static_cast<std::int64_t>(
            elapsed_ns > 0 ? static_cast<double>(elapsed_ns) * config_.max_drift_ppm * 1e-6 : 0.0);
        offset_ns_ += diff < allowance ? diff : allowance;
      }
    }
    if (device_ns > last_device_ns_) last_device_ns_ = device_ns;
    return device_ns + offset_ns_;
  }

  std::int64_t offset_ns() const { return offset_ns_; }
  std::uint64_t resets() const { return resets_; }
  bool initialised() const { return initialised_; }

 private:
  Config config_;
  bool initialised_ = false;
  std::int64_t offset_ns_ = 0;
  std::int64_t last_device_ns_ = INT64_MIN;
  std::uint64_t resets_ = 0;
};

}  // namespace msgraphs
