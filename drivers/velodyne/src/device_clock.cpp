// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/velodyne/device_clock.hpp"

#include "msgraphs/drivers/velodyne/packet_format.hpp"

namespace msgraphs::drivers::velodyne {
namespace {
constexpr std::int64_t kHalfHourUs = 1'800'000'000;
}  // namespace

UnixTime DeviceClockSync::Map(UnixTime arrival, std::uint32_t device_time_us,
                              std::uint32_t packet_duration_ns) {
  std::int64_t hour = hours_;
  if (!filter_.initialised()) {  // the first packet: nothing to unwrap against
    last_device_us_ = device_time_us;
  } else {
    const std::int64_t step = static_cast<std::int64_t>(device_time_us) - last_device_us_;
    if (step < -kHalfHourUs) {  // wrapped past the top of the hour
      hour = ++hours_;
      ++hour_wraps_;
      last_device_us_ = device_time_us;
    } else if (step > kHalfHourUs) {  // a late packet from before the wrap
      hour = hours_ - 1;
    } else if (step > 0) {
      last_device_us_ = device_time_us;
    }
  }
  const std::int64_t device_ns =
      (hour * static_cast<std::int64_t>(kMicrosecondsPerHour) + device_time_us) * 1000;
  // The packet arrives after its last firing: relate the arrival to that instant.
  const std::int64_t last_firing_ns = device_ns + packet_duration_ns;
  const std::int64_t host_last_firing_ns =
      filter_.Update(last_firing_ns, arrival.nanoseconds_since_epoch());
  return UnixTime::FromNanoseconds(host_last_firing_ns - packet_duration_ns);
}

}  // namespace msgraphs::drivers::velodyne
