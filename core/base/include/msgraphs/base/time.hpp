// SPDX-License-Identifier: MIT
// Strong time types. A Duration is a signed count of nanoseconds. A TimePoint is tagged with
// the clock it was read from, so a host-monotonic deadline can never be compared with a
// sensor stamp by accident (that is a compile error, not a bug to find on the robot).
//
// Clocks (who reads them: platform; base only defines the types):
//  - SteadyTime: the host's monotonic clock (CLOCK_MONOTONIC). Deadlines, rates, latencies.
//  - UnixTime:   nanoseconds since 1970-01-01 UTC. Stamps of recorded and live data (pcap and
//                candump stamps are UNIX time). Clocks of different robots are NOT synchronised.
#pragma once

#include <compare>
#include <cstdint>

namespace msgraphs {

class Duration {
 public:
  constexpr Duration() = default;
  static constexpr Duration FromNanoseconds(std::int64_t ns) { return Duration(ns); }
  static constexpr Duration FromMicroseconds(std::int64_t us) { return Duration(us * 1000); }
  static constexpr Duration FromMilliseconds(std::int64_t ms) { return Duration(ms * 1000000); }
  /// Rounds to the nearest nanosecond.
  static constexpr Duration FromSeconds(double s) {
    const double ns = s * 1e9;
    return Duration(static_cast<std::int64_t>(ns < 0.0 ? ns - 0.5 : ns + 0.5));
  }

  constexpr std::int64_t nanoseconds() const { return ns_; }
  constexpr double seconds() const { return static_cast<double>(ns_) * 1e-9; }

  constexpr auto operator<=>(const Duration&) const = default;
  constexpr Duration operator+(Duration o) const { return Duration(ns_ + o.ns_); }
  constexpr Duration operator-(Duration o) const { return Duration(ns_ - o.ns_); }
  constexpr Duration operator-() const { return Duration(-ns_); }
  constexpr Duration operator*(std::int64_t k) const { return Duration(ns_ * k); }
  constexpr Duration operator/(std::int64_t k) const { return Duration(ns_ / k); }
  constexpr Duration& operator+=(Duration o) { ns_ += o.ns_; return *this; }
  constexpr Duration& operator-=(Duration o) { ns_ -= o.ns_; return *this; }

 private:
  constexpr explicit Duration(std::int64_t ns) : ns_(ns) {}
  std::int64_t ns_ = 0;
};

template <typename ClockTag>
class TimePoint {
 public:
  constexpr TimePoint() = default;
  static constexpr TimePoint FromNanoseconds(std::int64_t ns_since_epoch) {
    return TimePoint(ns_since_epoch);
  }
  static constexpr TimePoint FromSeconds(double s_since_epoch) {
    return TimePoint(Duration::FromSeconds(s_since_epoch).nanoseconds());
  }

  constexpr std::int64_t nanoseconds_since_epoch() const { return ns_; }
  /// Seconds since the epoch. A double keeps ~0.2 us resolution for present-day UNIX time:
  /// enough for output files, not for arithmetic; subtract TimePoints instead.
  constexpr double seconds_since_epoch() const { return static_cast<double>(ns_) * 1e-9; }

  constexpr auto operator<=>(const TimePoint&) const = default;
  constexpr TimePoint operator+(Duration d) const { return TimePoint(ns_ + d.nanoseconds()); }
  constexpr TimePoint operator-(Duration d) const { return TimePoint(ns_ - d.nanoseconds()); }
  constexpr Duration operator-(TimePoint o) const {
    return Duration::FromNanoseconds(ns_ - o.ns_);
  }
  constexpr TimePoint& operator+=(Duration d) { ns_ += d.nanoseconds(); return *this; }

 private:
  constexpr explicit TimePoint(std::int64_t ns) : ns_(ns) {}
  std::int64_t ns_ = 0;
};

struct SteadyClockTag {};
struct UnixClockTag {};
using SteadyTime = TimePoint<SteadyClockTag>;
using UnixTime = TimePoint<UnixClockTag>;

}  // namespace msgraphs
