// SPDX-License-Identifier: MIT
// Contract violations: a bug in the caller or in msgraphs, never bad input. They stop the
// process through a fail handler that the runtime installs (to log and flush before abort).
//
// MSGRAPHS_ASSERT is on in every build, so keep its condition O(1). MSGRAPHS_DEBUG_ASSERT is for
// expensive checks and compiles away under NDEBUG.
#pragma once

namespace msgraphs {

/// What failed, where. All pointers refer to static storage (string literals, __FILE__).
struct FailureRecord {
  const char* expression = "";
  const char* message = "";
  const char* file = "";
  int line = 0;
};

/// A fail handler must not return (abort, or throw in a test build). If it returns anyway,
/// ContractViolation calls std::abort().
using FailHandler = void (*)(const FailureRecord& record);

/// Installs `handler` process-wide (nullptr restores the default) and returns the previous one.
/// The default handler records the failure (LastFailure()) and aborts without any I/O, because
/// base has none; platform::InstallStderrFailHandler() adds a message on stderr.
FailHandler SetFailHandler(FailHandler handler) noexcept;

/// The most recent failure, kept in static storage so a crash handler or debugger can read it.
const FailureRecord& LastFailure() noexcept;

[[noreturn]] void ContractViolation(const char* expression, const char* message, const char* file,
                                    int line);

}  // namespace msgraphs

#define MSGRAPHS_ASSERT(cond, msg)                                                 \
  (static_cast<bool>(cond) ? static_cast<void>(0)                                  \
                           : ::msgraphs::ContractViolation(#cond, msg, __FILE__, __LINE__))

#ifdef NDEBUG
#define MSGRAPHS_DEBUG_ASSERT(cond, msg) static_cast<void>(0)
#else
#define MSGRAPHS_DEBUG_ASSERT(cond, msg) MSGRAPHS_ASSERT(cond, msg)
#endif
