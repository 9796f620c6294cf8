// SPDX-License-Identifier: MIT
#include "msgraphs/base/assert.hpp"

#include <atomic>
#include <cstdlib>

namespace msgraphs {
namespace {

FailureRecord g_last_failure;

void DefaultFailHandler(const FailureRecord& /*record*/) { std::abort(); }

std::atomic<FailHandler> g_handler{&DefaultFailHandler};

}  // namespace

FailHandler SetFailHandler(FailHandler handler) noexcept {
  return g_handler.exchange(handler != nullptr ? handler : &DefaultFailHandler);
}

const FailureRecord& LastFailure() noexcept { return g_last_failure; }

void ContractViolation(const char* expression, const char* message, const char* file, int line) {
  g_last_failure = FailureRecord{expression, message, file, line};
  g_handler.load()(g_last_failure);
  std::abort();  // the handler returned: not allowed
}

}  // namespace msgraphs
