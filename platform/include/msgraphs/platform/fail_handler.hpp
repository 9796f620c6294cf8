// SPDX-License-Identifier: MIT
#pragma once

namespace msgraphs::platform {

/// Installs a base fail handler that writes the contract violation (expression, message,
/// file:line) to stderr with write(2), which is async-signal-safe and allocation-free, then
/// aborts. Call once at program start; tests and tools get it from their main().
void InstallStderrFailHandler() noexcept;

}  // namespace msgraphs::platform
