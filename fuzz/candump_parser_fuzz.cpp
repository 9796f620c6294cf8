// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary text as candump log lines. Invariants: no crash; every parsed
// classic frame formats back to a line that parses to the same frame and time.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "msgraphs/drivers/can_odometry/candump.hpp"

using namespace msgraphs;
using namespace msgraphs::drivers::can_odometry;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    const std::string_view line = text.substr(0, nl);
    text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
    auto parsed = ParseCandumpLine(line);
    if (!parsed || parsed->kind != CandumpLine::Kind::kFrame) continue;
    const CandumpLine& a = *parsed;
    if (a.frame.length > 8) std::abort();
    char buffer[kMaxCandumpLine];
    auto n = FormatCandumpLine(a.stamp, a.interface_name(), a.frame, CandumpPrecision::kNanoseconds, buffer);
    if (!n) continue;  // e.g. a timestamp beyond what the format holds
    auto b = ParseCandumpLine({buffer, *n});
    if (!b || b->frame.id != a.frame.id || b->frame.length != a.frame.length || b->stamp != a.stamp ||
        b->frame.extended != a.frame.extended || b->frame.remote != a.frame.remote ||
        b->frame.error != a.frame.error) {
      std::abort();
    }
    for (std::size_t i = 0; i < a.frame.length && !a.frame.remote; ++i) {
      if (a.frame.data[i] != b->frame.data[i]) std::abort();
    }
  }
  return 0;
}
