// SPDX-License-Identifier: MIT
#include "msgraphs/platform/realtime.hpp"

#include <gtest/gtest.h>

#include <pthread.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstdlib>

#include <thread>

namespace msgraphs::platform {
namespace {

TEST(Realtime, OutOfRangePriorityIsInvalidArgument) {
  const Status s = SetCurrentThreadRealtime(1000);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code, Errc::kInvalidArgument);
}

TEST(Realtime, ProbeAgreesWithAnActualAttempt) {
  const RealtimeCapabilities caps = ProbeRealtimeCapabilities();
  EXPECT_GE(caps.max_fifo_priority, 1);
  // Try for real on a separate thread: the outcome must match the probe, and a refusal must
  // say "permission denied" rather than fail some other way.
  Status attempt = Ok();
  std::thread t([&attempt] { attempt = SetCurrentThreadRealtime(1); });
  t.join();
  EXPECT_EQ(attempt.has_value(), caps.can_use_fifo);
  if (!attempt) {
    EXPECT_EQ(attempt.error().code, Errc::kPermissionDenied);
  }
}

// mlockall changes the whole process, so it runs in a forked child. Exit 0: locked; 3: refused
// with a clear reason (no privilege, or RLIMIT_MEMLOCK below the process size); 4: anything else.
// Skipped under ASan, whose terabyte shadow mappings cannot be locked.
#if !defined(__SANITIZE_ADDRESS__)
TEST(RealtimeDeathTest, LockProcessMemoryLocksOrExplains) {
  const auto child = [] {
    const Status s = LockProcessMemory(512 * 1024);
    if (s) std::_Exit(0);
    const bool explained = s.error().code == Errc::kPermissionDenied ||
                           (s.error().code == Errc::kIo && s.error().sys_errno == ENOMEM);
    std::_Exit(explained ? 3 : 4);
  };
  EXPECT_EXIT(child(), [](int status) {
    return WIFEXITED(status) && (WEXITSTATUS(status) == 0 || WEXITSTATUS(status) == 3);
  }, "");
}
#endif

TEST(Realtime, ThreadNameIsTruncatedTo15Characters) {
  std::thread t([] {
    ASSERT_TRUE(SetCurrentThreadName("msgraphs-lidar-receive"));
    char name[32] = {};
    pthread_getname_np(pthread_self(), name, sizeof(name));
    EXPECT_STREQ(name, "msgraphs-lidar-");
  });
  t.join();
}

}  // namespace
}  // namespace msgraphs::platform
