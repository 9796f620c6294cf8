// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/velodyne/position_packet.hpp"

#include "msgraphs/drivers/velodyne/packet_format.hpp"

namespace msgraphs::drivers::velodyne {
namespace {

constexpr std::size_t kTopTempOffset = 187;
constexpr std::size_t kBottomTempOffset = 188;
constexpr std::size_t kTimeOffset = 198;
constexpr std::size_t kPpsOffset = 202;
constexpr std::size_t kNmeaOffset = 206;
constexpr std::size_t kNmeaBytes = 128;

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

bool ParseDigits(std::string_view s, int& out) {
  if (s.empty()) return false;
  int v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  out = v;
  return true;
}

// Field `index` (0 = sentence type) of a comma-separated body.
std::string_view Field(std::string_view body, int index) {
  for (int i = 0; i < index; ++i) {
    const auto comma = body.find(',');
    if (comma == std::string_view::npos) return {};
    body.remove_prefix(comma + 1);
  }
  return body.substr(0, body.find(','));
}

}  // namespace

NmeaFix ParseNmea(std::string_view sentence) {
  NmeaFix fix;
  while (!sentence.empty() && (sentence.back() == '\r' || sentence.back() == '\n')) {
    sentence.remove_suffix(1);
  }
  if (sentence.empty()) return fix;
  if (sentence.front() == '$') sentence.remove_prefix(1);
  std::string_view body = sentence;
  if (const auto star = sentence.find('*'); star != std::string_view::npos) {
    body = sentence.substr(0, star);
    const std::string_view sum = sentence.substr(star + 1);
    if (sum.size() >= 2 && HexValue(sum[0]) >= 0 && HexValue(sum[1]) >= 0) {
      unsigned x = 0;
      for (char c : body) x ^= static_cast<unsigned char>(c);
      fix.checksum_ok = x == static_cast<unsigned>(HexValue(sum[0]) * 16 + HexValue(sum[1]));
    }
  }
  const std::string_view type = Field(body, 0);
  if (type.size() != 5 || type.substr(2) != "RMC") {
    fix.kind = NmeaFix::Kind::kOther;
    return fix;
  }
  fix.kind = NmeaFix::Kind::kRmc;
  const std::string_view time = Field(body, 1);  // hhmmss[.ss]
  int hh = 0, mm = 0, ss = 0;
  if (time.size() >= 6 && ParseDigits(time.substr(0, 2), hh) && ParseDigits(time.substr(2, 2), mm) &&
      ParseDigits(time.substr(4, 2), ss) && hh < 24 && mm < 60 && ss < 61) {
    double fraction = 0.0;
    if (time.size() > 7 && time[6] == '.') {
      double scale = 0.1;
      for (char c : time.substr(7)) {
        if (c < '0' || c > '9') break;
        fraction += scale * (c - '0');
        scale *= 0.1;
      }
    }
    fix.utc_hour = hh;
    fix.utc_minute = mm;
    fix.utc_second = ss + fraction;
  }
  fix.valid = Field(body, 2) == "A";
  const std::string_view date = Field(body, 9);  // ddmmyy
  int dd = 0, mo = 0, yy = 0;
  if (date.size() == 6 && ParseDigits(date.substr(0, 2), dd) && ParseDigits(date.substr(2, 2), mo) &&
      ParseDigits(date.substr(4, 2), yy) && dd >= 1 && dd <= 31 && mo >= 1 && mo <= 12) {
    fix.day = dd;
    fix.month = mo;
    fix.year = 2000 + yy;
  }
  return fix;
}

Expected<PositionPacket> DecodePositionPacket(std::span<const std::uint8_t> payload) {
  if (payload.size() != kPositionPacketBytes) {
    return Error{Errc::kMalformed, "velodyne: position packet is not 512 bytes"};
  }
  PositionPacket packet;
  packet.device_time_us = ReadU32Le(payload.data() + kTimeOffset);
  if (packet.device_time_us >= kMicrosecondsPerHour) {
    return Error{Errc::kMalformed, "velodyne: position packet time beyond one hour"};
  }
  const std::uint8_t pps = payload[kPpsOffset];
  if (pps > 3) return Error{Errc::kMalformed, "velodyne: PPS status above 3"};
  packet.pps = static_cast<PpsStatus>(pps);
  packet.temperature_top_c = payload[kTopTempOffset];
  packet.temperature_bottom_c = payload[kBottomTempOffset];
  std::size_t length = 0;
  while (length < kNmeaBytes && payload[kNmeaOffset + length] != 0) {
    const auto c = static_cast<char>(payload[kNmeaOffset + length]);
    packet.nmea[length] = c;
    ++length;
  }
  packet.nmea[length] = '\0';
  packet.nmea_length = static_cast<std::uint8_t>(length);
  packet.fix = ParseNmea(packet.nmea_sentence());
  return packet;
}

}  // namespace msgraphs::drivers::velodyne
