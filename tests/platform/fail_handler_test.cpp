// SPDX-License-Identifier: MIT
#include "msgraphs/platform/fail_handler.hpp"

#include <gtest/gtest.h>

#include "msgraphs/base/assert.hpp"

namespace msgraphs::platform {
namespace {

TEST(FailHandlerDeathTest, PrintsExpressionMessageAndLocation) {
  InstallStderrFailHandler();
  EXPECT_DEATH(MSGRAPHS_ASSERT(1 > 2, "queue index"),
               "contract violation: queue index \\[1 > 2\\] at .*fail_handler_test.cpp:[0-9]+");
}

}  // namespace
}  // namespace msgraphs::platform
