// SPDX-License-Identifier: MIT
#include "msgraphs/base/expected.hpp"

#include <gtest/gtest.h>

#include <string>

namespace msgraphs {
namespace {

Expected<int> ParsePositive(int v) {
  if (v <= 0) return Error{Errc::kInvalidArgument, "must be positive"};
  return v;
}

Status CheckEven(int v) {
  if (v % 2 != 0) return Error{Errc::kMalformed, "odd"};
  return Ok();
}

TEST(Expected, CarriesValueOrError) {
  const Expected<int> ok = ParsePositive(3);
  ASSERT_TRUE(ok.has_value());
  EXPECT_EQ(*ok, 3);
  const Expected<int> bad = ParsePositive(-1);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, Errc::kInvalidArgument);
  EXPECT_STREQ(bad.error().detail, "must be positive");
  EXPECT_EQ(bad.value_or(7), 7);
}

TEST(Expected, MovesNonTrivialValues) {
  Expected<std::string> s = std::string(100, 'x');
  std::string moved = std::move(s).value();
  EXPECT_EQ(moved.size(), 100u);
}

TEST(Status, OkAndError) {
  EXPECT_TRUE(CheckEven(2));
  const Status odd = CheckEven(3);
  ASSERT_FALSE(odd);
  EXPECT_EQ(odd.error().code, Errc::kMalformed);
}

TEST(Errc, EveryCodeHasAName) {
  for (int c = 0; c <= static_cast<int>(Errc::kInvalidConfig); ++c) {
    EXPECT_STRNE(ToString(static_cast<Errc>(c)), "unknown error") << c;
  }
}

TEST(ExpectedDeathTest, ValueOfAnErrorIsAContractViolation) {
  const Expected<int> bad = ParsePositive(0);
  EXPECT_DEATH(static_cast<void>(bad.value()), "Expected::value\\(\\) on an error");
}

}  // namespace
}  // namespace msgraphs
