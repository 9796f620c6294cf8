// SPDX-License-Identifier: MIT
#include "msgraphs/platform/clock.hpp"

#include <cerrno>
#include <ctime>

namespace msgraphs::platform {
namespace {

std::int64_t ToNanoseconds(const timespec& ts) {
  return std::int64_t{ts.tv_sec} * 1000000000 + std::int64_t{ts.tv_nsec};
}

}  // namespace

SteadyTime SteadyNow() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return SteadyTime::FromNanoseconds(ToNanoseconds(ts));
}

UnixTime UnixNow() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return UnixTime::FromNanoseconds(ToNanoseconds(ts));
}

Duration SteadyResolution() noexcept {
  timespec ts{};
  clock_getres(CLOCK_MONOTONIC, &ts);
  return Duration::FromNanoseconds(ToNanoseconds(ts));
}

void SleepUntil(SteadyTime deadline) noexcept {
  const std::int64_t ns = deadline.nanoseconds_since_epoch();
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(ns / 1000000000);
  ts.tv_nsec = static_cast<long>(ns % 1000000000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

timespec RemainingUntil(SteadyTime deadline) noexcept {
  std::int64_t ns = (deadline - SteadyNow()).nanoseconds();
  if (ns < 0) ns = 0;
  return timespec{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
}

}  // namespace msgraphs::platform
