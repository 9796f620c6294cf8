// SPDX-License-Identifier: MIT
#include "msgraphs/base/assert.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace msgraphs {
namespace {

struct ContractError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

[[noreturn]] void ThrowingHandler(const FailureRecord& record) { throw ContractError(record.message); }

TEST(Assert, PassingConditionDoesNothing) {
  MSGRAPHS_ASSERT(1 + 1 == 2, "arithmetic");
  SUCCEED();
}

TEST(Assert, InstalledHandlerReceivesTheRecord) {
  const FailHandler previous = SetFailHandler(&ThrowingHandler);
  const int line = __LINE__ + 1;
  EXPECT_THROW(MSGRAPHS_ASSERT(2 < 1, "two is not less than one"), ContractError);
  SetFailHandler(previous);
  EXPECT_STREQ(LastFailure().message, "two is not less than one");
  EXPECT_STREQ(LastFailure().expression, "2 < 1");
  EXPECT_EQ(LastFailure().line, line);
}

TEST(AssertDeathTest, DefaultPathAbortsWithMessage) {
  EXPECT_DEATH(MSGRAPHS_ASSERT(false, "boom"), "contract violation: boom");
}

}  // namespace
}  // namespace msgraphs
