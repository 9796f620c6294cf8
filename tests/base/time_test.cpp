// SPDX-License-Identifier: MIT
#include "msgraphs/base/time.hpp"

#include <gtest/gtest.h>

#include <type_traits>

namespace msgraphs {
namespace {

TEST(Duration, ConversionsAndArithmetic) {
  EXPECT_EQ(Duration::FromMilliseconds(3).nanoseconds(), 3000000);
  EXPECT_EQ(Duration::FromMicroseconds(55).nanoseconds(), 55000);
  EXPECT_EQ(Duration::FromSeconds(0.1).nanoseconds(), 100000000);
  EXPECT_EQ(Duration::FromSeconds(-2.3e-9).nanoseconds(), -2);  // rounds, not truncates
  EXPECT_DOUBLE_EQ((Duration::FromMilliseconds(1500)).seconds(), 1.5);
  EXPECT_LT(Duration::FromMilliseconds(1), Duration::FromMilliseconds(2));
  EXPECT_EQ((Duration::FromMilliseconds(10) * 3 / 2).nanoseconds(), 15000000);
}

TEST(TimePoint, DifferenceIsADuration) {
  // A present-day UNIX time keeps full nanosecond precision as an integer.
  const UnixTime t0 = UnixTime::FromNanoseconds(1700000000123456789);
  const UnixTime t1 = t0 + Duration::FromMicroseconds(55);
  EXPECT_EQ((t1 - t0).nanoseconds(), 55000);
  EXPECT_EQ(t1.nanoseconds_since_epoch(), 1700000000123511789);
  EXPECT_GT(t1, t0);
}

TEST(TimePoint, ClocksDoNotMix) {
  // Comparing a host-monotonic time with a data stamp must not compile.
  static_assert(!std::is_convertible_v<SteadyTime, UnixTime>);
  static_assert(!std::is_convertible_v<UnixTime, SteadyTime>);
  static_assert(!std::is_convertible_v<std::int64_t, Duration>);
  SUCCEED();
}

}  // namespace
}  // namespace msgraphs
