// SPDX-License-Identifier: MIT
// Real-time process setup: memory locking and SCHED_FIFO. Each call returns a Status instead of
// failing hard, because a developer's machine usually lacks the privileges (CAP_SYS_NICE,
// CAP_IPC_LOCK or a large RLIMIT_MEMLOCK) that the robot's payload computer grants; the node
// reports what it got in its startup banner.
#pragma once

#include <cstddef>
#include <cstdint>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::platform {

/// mlockall(MCL_CURRENT | MCL_FUTURE), then touches `stack_prefault_bytes` of the calling
/// thread's stack so later page faults cannot stall it. `stack_prefault_bytes` must stay well
/// below the calling thread's stack size (it is reserved in one frame). kPermissionDenied without
/// privilege; kIo with ENOMEM when RLIMIT_MEMLOCK is smaller than the process.
Status LockProcessMemory(std::size_t stack_prefault_bytes = 256 * 1024);

/// Moves the calling thread to SCHED_FIFO at `priority` (1..99). kPermissionDenied without
/// privilege, kInvalidArgument outside the range.
Status SetCurrentThreadRealtime(int priority);

/// Names the calling thread (shown by top/ps/gdb); at most 15 characters are kept.
Status SetCurrentThreadName(const char* name);

/// What this process may do, found without changing anything (a throw-away thread tries
/// SCHED_FIFO; mlock of one page tries locking).
struct RealtimeCapabilities {
  bool can_use_fifo = false;
  int max_fifo_priority = 0;
  bool can_lock_memory = false;
  std::int64_t memlock_limit_bytes = -1;  ///< RLIMIT_MEMLOCK soft limit; -1 means unlimited
};
RealtimeCapabilities ProbeRealtimeCapabilities();

}  // namespace msgraphs::platform
