// SPDX-License-Identifier: MIT
// The host's clocks as msgraphs time types. Never allocates; safe from any thread.
#pragma once

#include <ctime>

#include "msgraphs/base/time.hpp"

namespace msgraphs::platform {

/// CLOCK_MONOTONIC: for deadlines, rates and latencies. Unaffected by NTP steps.
SteadyTime SteadyNow() noexcept;
/// CLOCK_REALTIME as UNIX time: for stamping live data the way recordings are stamped.
UnixTime UnixNow() noexcept;
/// Resolution of CLOCK_MONOTONIC as the kernel reports it.
Duration SteadyResolution() noexcept;
/// Sleeps until `deadline` on CLOCK_MONOTONIC (absolute, so periodic loops do not drift);
/// resumes after signals until the deadline has passed.
void SleepUntil(SteadyTime deadline) noexcept;
/// The time left until `deadline` (zero once it has passed), as the relative timeout the OS's
/// waits (ppoll, gpiod_line_event_wait) take.
timespec RemainingUntil(SteadyTime deadline) noexcept;

}  // namespace msgraphs::platform
