// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/can_odometry/candump.hpp"

namespace msgraphs::drivers::can_odometry {
namespace {

constexpr std::uint32_t kCanErrFlag = 0x20000000u;

int Hex(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}
bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

std::string_view NextToken(std::string_view& rest) {
  while (!rest.empty() && IsSpace(rest.front())) rest.remove_prefix(1);
  std::size_t n = 0;
  while (n < rest.size() && !IsSpace(rest[n])) ++n;
  const std::string_view token = rest.substr(0, n);
  rest.remove_prefix(n);
  return token;
}

// Classic data: hex pairs with optional '.' separators, optional "_L" DLC suffix.
Expected<CandumpLine> ParseClassic(std::string_view id_text, std::string_view data, CandumpLine line) {
  if (id_text.size() != 3 && id_text.size() != 8) {
    return Error{Errc::kMalformed, "candump: CAN id must have 3 or 8 hex digits"};
  }
  std::uint32_t id = 0;
  for (char c : id_text) {
    const int h = Hex(c);
    if (h < 0) return Error{Errc::kMalformed, "candump: CAN id is not hex"};
    id = (id << 4) | static_cast<std::uint32_t>(h);
  }
  CanFrame& f = line.frame;
  if (id_text.size() == 8) {
    f.error = (id & kCanErrFlag) != 0;
    f.extended = !f.error;
    f.id = id & 0x1FFFFFFFu;
    if (id > 0x3FFFFFFFu) return Error{Errc::kMalformed, "candump: extended id beyond 29 bits"};
  } else {
    if (id > 0x7FFu) return Error{Errc::kMalformed, "candump: standard id beyond 11 bits"};
    f.id = id;
  }
  if (!data.empty() && (data.front() == 'R' || data.front() == 'r')) {
    f.remote = true;
    data.remove_prefix(1);
    if (!data.empty()) {
      const int len = Hex(data.front());
      if (len < 0 || len > 8) return Error{Errc::kMalformed, "candump: bad RTR length"};
      f.length = static_cast<std::uint8_t>(len);
      data.remove_prefix(1);
      if (!data.empty() && data.front() == '_') data = {};  // "_<dlc>" for len 8: accepted
      if (!data.empty()) return Error{Errc::kMalformed, "candump: trailing text after RTR"};
    }
    line.kind = CandumpLine::Kind::kFrame;
    return line;
  }
  std::size_t n = 0;
  while (!data.empty()) {
    if (data.front() == '.') {
      data.remove_prefix(1);
      continue;
    }
    if (data.front() == '_') {  // raw DLC 9..F for an 8-byte frame
      if (n != 8 || data.size() != 2 || Hex(data[1]) < 9) {
        return Error{Errc::kMalformed, "candump: bad DLC suffix"};
      }
      break;
    }
    if (data.size() < 2 || Hex(data[0]) < 0 || Hex(data[1]) < 0) {
      return Error{Errc::kMalformed, "candump: data is not hex pairs"};
    }
    if (n == 8) return Error{Errc::kMalformed, "candump: more than 8 data bytes in a classic frame"};
    f.data[n++] = static_cast<std::uint8_t>(Hex(data[0]) * 16 + Hex(data[1]));
    data.remove_prefix(2);
  }
  f.length = static_cast<std::uint8_t>(n);
  line.kind = CandumpLine::Kind::kFrame;
  return line;
}

}  // namespace

Expected<CandumpLine> ParseCandumpLine(std::string_view text) {
  CandumpLine line;
  std::string_view rest = text;
  while (!rest.empty() && IsSpace(rest.front())) rest.remove_prefix(1);
  if (rest.empty() || rest.front() != '(') return line;  // comment (canplayer's rule)

  // "(seconds.fraction)" with 6 or 9 decimals.
  const std::size_t close = rest.find(')');
  if (close == std::string_view::npos) return Error{Errc::kMalformed, "candump: no ')' after time"};
  const std::string_view stamp = rest.substr(1, close - 1);
  rest.remove_prefix(close + 1);
  const std::size_t dot = stamp.find('.');
  if (dot == std::string_view::npos || dot == 0) {
    return Error{Errc::kMalformed, "candump: timestamp needs seconds.fraction"};
  }
  const std::string_view whole = stamp.substr(0, dot);
  const std::string_view fraction = stamp.substr(dot + 1);
  if (fraction.size() != 6 && fraction.size() != 9) {
    return Error{Errc::kMalformed, "candump: timestamp needs 6 or 9 decimals"};
  }
  if (whole.size() > 12) return Error{Errc::kMalformed, "candump: timestamp seconds too large"};
  std::int64_t seconds = 0, sub = 0;
  for (char c : whole) {
    if (c < '0' || c > '9') return Error{Errc::kMalformed, "candump: timestamp is not decimal"};
    seconds = seconds * 10 + (c - '0');
  }
  for (char c : fraction) {
    if (c < '0' || c > '9') return Error{Errc::kMalformed, "candump: timestamp is not decimal"};
    sub = sub * 10 + (c - '0');
  }
  // Time is kept as int64 nanoseconds: years beyond 2255 do not fit (found by fuzzing).
  if (seconds > 9'000'000'000) return Error{Errc::kMalformed, "candump: timestamp beyond the year 2255"};
  if (fraction.size() == 6) sub *= 1000;
  line.stamp = UnixTime::FromNanoseconds(seconds * 1'000'000'000 + sub);

  const std::string_view interface = NextToken(rest);
  if (interface.empty() || interface.size() >= kMaxInterfaceName) {
    return Error{Errc::kMalformed, "candump: missing or over-long interface name"};
  }
  for (std::size_t i = 0; i < interface.size(); ++i) line.interface[i] = interface[i];

  const std::string_view frame = NextToken(rest);
  const std::string_view flag = NextToken(rest);  // optional R/T direction
  if (!flag.empty() && flag != "R" && flag != "T") {
    return Error{Errc::kMalformed, "candump: unexpected text after the frame"};
  }
  if (!NextToken(rest).empty()) return Error{Errc::kMalformed, "candump: unexpected text after the frame"};

  const std::size_t hash = frame.find('#');
  if (hash == std::string_view::npos) return Error{Errc::kMalformed, "candump: frame has no '#'"};
  const std::string_view id_text = frame.substr(0, hash);
  const std::string_view after = frame.substr(hash + 1);
  if (!after.empty() && after.front() == '#') {
    // CAN FD "<id>##<flags nibble><data>": check the shape, then report it as skipped.
    if (after.size() < 2 || Hex(after[1]) < 0 || (after.size() - 2) % 2 != 0 ||
        (after.size() - 2) / 2 > 64) {
      return Error{Errc::kMalformed, "candump: bad CAN FD frame"};
    }
    line.kind = CandumpLine::Kind::kCanFd;
    return line;
  }
  if (after.find('#') != std::string_view::npos) {
    line.kind = CandumpLine::Kind::kCanXl;  // "<prio/vcid>#<flags>:<sdt>:<af>#<data>"
    return line;
  }
  return ParseClassic(id_text, after, line);
}

Expected<std::size_t> FormatCandumpLine(UnixTime stamp, std::string_view interface,
                                        const CanFrame& frame, CandumpPrecision precision,
                                        std::span<char> out) {
  if (out.size() < kMaxCandumpLine) return Error{Errc::kCapacityExceeded, "candump: buffer too small"};
  if (interface.empty() || interface.size() >= kMaxInterfaceName) {
    return Error{Errc::kInvalidArgument, "candump: bad interface name"};
  }
  if (frame.length > 8) return Error{Errc::kInvalidArgument, "candump: classic frames carry 0..8 bytes"};
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::size_t n = 0;
  auto put = [&](char c) { out[n++] = c; };
  auto put_decimal = [&](std::int64_t v, int width) {
    char tmp[24];
    int k = 0;
    do {
      tmp[k++] = static_cast<char>('0' + v % 10);
      v /= 10;
    } while (v > 0);
    while (k < width) tmp[k++] = '0';
    while (k > 0) put(tmp[--k]);
  };
  std::int64_t ns = stamp.nanoseconds_since_epoch();
  if (ns < 0) ns = 0;
  put('(');
  put_decimal(ns / 1'000'000'000, 10);
  put('.');
  if (precision == CandumpPrecision::kNanoseconds) {
    put_decimal(ns % 1'000'000'000, 9);
  } else {
    put_decimal((ns % 1'000'000'000) / 1000, 6);
  }
  put(')');
  put(' ');
  for (char c : interface) put(c);
  put(' ');
  std::uint32_t id = frame.id;
  int digits = 3;
  if (frame.error) {
    id = (frame.id & 0x1FFFFFFFu) | kCanErrFlag;
    digits = 8;
  } else if (frame.extended) {
    digits = 8;
  }
  for (int i = digits - 1; i >= 0; --i) put(kDigits[(id >> (4 * i)) & 0xFu]);
  put('#');
  if (frame.remote) {
    put('R');
    if (frame.length > 0) put(kDigits[frame.length]);
  } else {
    for (std::size_t i = 0; i < frame.length; ++i) {
      put(kDigits[frame.data[i] >> 4]);
      put(kDigits[frame.data[i] & 0xFu]);
    }
  }
  put('\n');
  return n;
}

}  // namespace msgraphs::drivers::can_odometry
