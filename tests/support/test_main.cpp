// SPDX-License-Identifier: MIT
// main() of every test binary: contract violations print where they happened.
#include <gtest/gtest.h>

#include "msgraphs/platform/fail_handler.hpp"

int main(int argc, char** argv) {
  msgraphs::platform::InstallStderrFailHandler();
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
