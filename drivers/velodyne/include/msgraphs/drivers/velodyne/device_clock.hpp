// SPDX-License-Identifier: MIT
// Maps the sensor's "microseconds past the hour" packet time onto the host clock.
//
// Why not take the hour from host time: sensors without PPS lock drift freely, and on real
// captures host time modulo one hour sits ~30 minutes from the device time, where the usual
// "+-30 min window" picks the wrong hour (formats-and-references.md section 1.1). Instead the
// device time is unwrapped across hours and related to the host clock by the minimum observed
// (arrival - firing) delay: the lower envelope removes network and scheduling jitter while
// keeping the device's precise spacing between packets.
#pragma once

#include <cstdint>

#include "msgraphs/base/clock_offset_filter.hpp"
#include "msgraphs/base/time.hpp"

namespace msgraphs::drivers::velodyne {

class DeviceClockSync {
 public:
  DeviceClockSync() = default;
  explicit DeviceClockSync(const ClockOffsetFilter::Config& config) : filter_(config) {}

  /// `arrival` is the host time the packet arrived (kernel or pcap timestamp), `device_time_us`
  /// the packet's first-firing time past the hour, `packet_duration_ns` its firing span.
  /// Returns the host time of the packet's first firing.
  UnixTime Map(UnixTime arrival, std::uint32_t device_time_us, std::uint32_t packet_duration_ns);

  std::uint64_t resets() const { return filter_.resets(); }
  std::uint64_t hour_wraps() const { return hour_wraps_; }
  /// Current estimate of clock offset plus the arrival latency floor, nanoseconds.
  std::int64_t offset_ns() const { return filter_.offset_ns(); }

 private:
  ClockOffsetFilter filter_;
  std::uint32_t last_device_us_ = 0;
  std::int64_t hours_ = 0;
  std::uint64_t hour_wraps_ = 0;
};

}  // namespace msgraphs::drivers::velodyne
