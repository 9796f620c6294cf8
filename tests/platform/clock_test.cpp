// SPDX-License-Identifier: MIT
#include "msgraphs/platform/clock.hpp"

#include <gtest/gtest.h>

namespace msgraphs::platform {
namespace {

TEST(Clock, SteadyIsMonotonic) {
  SteadyTime prev = SteadyNow();
  for (int i = 0; i < 1000; ++i) {
    const SteadyTime now = SteadyNow();
    ASSERT_GE(now, prev);
    prev = now;
  }
  EXPECT_GT(SteadyResolution().nanoseconds(), 0);
}

TEST(Clock, UnixTimeIsPresentDay) {
  // After 2023-01-01 and before 2100: catches a clock read as the wrong unit or epoch.
  const double s = UnixNow().seconds_since_epoch();
  EXPECT_GT(s, 1672531200.0);
  EXPECT_LT(s, 4102444800.0);
}

TEST(Clock, SleepUntilDoesNotReturnEarly) {
  const SteadyTime deadline = SteadyNow() + Duration::FromMilliseconds(5);
  SleepUntil(deadline);
  EXPECT_GE(SteadyNow(), deadline);
}

}  // namespace
}  // namespace msgraphs::platform
