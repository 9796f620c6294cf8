// SPDX-License-Identifier: MIT
#include "msgraphs/platform/fail_handler.hpp"

#include <unistd.h>

#include <cstdlib>
#include <cstring>

#include "msgraphs/base/assert.hpp"

namespace msgraphs::platform {
namespace {

void WriteAll(const char* text) {
  std::size_t left = std::strlen(text);
  while (left > 0) {
    const ssize_t n = ::write(STDERR_FILENO, text, left);
    if (n <= 0) return;
    text += n;
    left -= static_cast<std::size_t>(n);
  }
}

// Formats the line number without printf (not async-signal-safe, may allocate).
void WriteLine(int line) {
  char digits[16];
  int i = 15;
  digits[i] = '\0';
  unsigned value = line < 0 ? 0u : static_cast<unsigned>(line);
  do {
    digits[--i] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value != 0 && i > 0);
  WriteAll(&digits[i]);
}

void StderrFailHandler(const FailureRecord& record) {
  WriteAll("msgraphs: contract violation: ");
  WriteAll(record.message);
  WriteAll(" [");
  WriteAll(record.expression);
  WriteAll("] at ");
  WriteAll(record.file);
  WriteAll(":");
  WriteLine(record.line);
  WriteAll("\n");
  std::abort();
}

}  // namespace

void InstallStderrFailHandler() noexcept { SetFailHandler(&StderrFailHandler); }

}  // namespace msgraphs::platform
