// SPDX-License-Identifier: MIT
#include "msgraphs/platform/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <thread>

namespace msgraphs::platform {
namespace {

Error FromErrno(int err, const char* detail) {
  const Errc code = (err == EPERM || err == EACCES) ? Errc::kPermissionDenied
                    : (err == EINVAL)               ? Errc::kInvalidArgument
                                                    : Errc::kIo;
  return Error{code, detail, err};
}

// Touches `bytes` of stack below the caller so those pages are resident (and, after mlockall,
// locked) before the real-time loop needs them. alloca moves the stack pointer by the whole
// amount in one frame; a loop over a fixed local array would touch the same page again and again.
void PrefaultStack(std::size_t bytes) {
  constexpr std::size_t kPage = 4096;
  auto* stack = static_cast<volatile unsigned char*>(__builtin_alloca(bytes));
  for (std::size_t offset = 0; offset < bytes; offset += kPage) stack[offset] = 0;
}

}  // namespace

Status LockProcessMemory(std::size_t stack_prefault_bytes) {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    return FromErrno(errno, "mlockall(MCL_CURRENT|MCL_FUTURE) failed");
  }
  PrefaultStack(stack_prefault_bytes);
  return Ok();
}

Status SetCurrentThreadRealtime(int priority) {
  const int lo = sched_get_priority_min(SCHED_FIFO);
  const int hi = sched_get_priority_max(SCHED_FIFO);
  if (priority < lo || priority > hi) {
    return Error{Errc::kInvalidArgument, "SCHED_FIFO priority out of range", 0};
  }
  sched_param param{};
  param.sched_priority = priority;
  const int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  if (err != 0) return FromErrno(err, "pthread_setschedparam(SCHED_FIFO) failed");
  return Ok();
}

Status SetCurrentThreadName(const char* name) {
  char truncated[16] = {};
  std::strncpy(truncated, name, sizeof(truncated) - 1);
  const int err = pthread_setname_np(pthread_self(), truncated);
  if (err != 0) return FromErrno(err, "pthread_setname_np failed");
  return Ok();
}

RealtimeCapabilities ProbeRealtimeCapabilities() {
  RealtimeCapabilities caps;
  caps.max_fifo_priority = sched_get_priority_max(SCHED_FIFO);

  // Try SCHED_FIFO on a throw-away thread so the caller's scheduling is untouched.
  std::thread probe([&caps] { caps.can_use_fifo = SetCurrentThreadRealtime(1).has_value(); });
  probe.join();

  rlimit limit{};
  if (getrlimit(RLIMIT_MEMLOCK, &limit) == 0) {
    caps.memlock_limit_bytes =
        limit.rlim_cur == RLIM_INFINITY ? -1 : static_cast<std::int64_t>(limit.rlim_cur);
  }
  // Locking one page says whether mlock works at all; mlockall's full success also depends on
  // the process size versus the limit, which the banner shows beside this.
  static unsigned char page[4096];
  if (mlock(page, sizeof(page)) == 0) {
    caps.can_lock_memory = true;
    munlock(page, sizeof(page));
  }
  return caps;
}

}  // namespace msgraphs::platform
