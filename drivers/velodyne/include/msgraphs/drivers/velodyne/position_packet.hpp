// SPDX-License-Identifier: MIT
// Pure decoder of the 512-byte position (telemetry) packet sent to port 8308: device time, PPS
// lock state and the GPS NMEA sentence the sensor forwards.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string_view>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::drivers::velodyne {

enum class PpsStatus : std::uint8_t { kAbsent = 0, kSynchronizing = 1, kLocked = 2, kError = 3 };

/// What the NMEA field says once parsed (GPRMC/GNRMC only; other sentences keep kind kOther).
struct NmeaFix {
  enum class Kind : std::uint8_t { kNone, kRmc, kOther } kind = Kind::kNone;
  bool checksum_ok = false;  ///< a '*hh' checksum was present and matched
  bool valid = false;        ///< RMC status 'A'
  int utc_hour = -1, utc_minute = -1;
  double utc_second = -1.0;
  int day = -1, month = -1, year = -1;  ///< year as 4 digits (2000 + yy) when a date is present
};

struct PositionPacket {
  std::uint32_t device_time_us = 0;  ///< microseconds past the hour
  PpsStatus pps = PpsStatus::kAbsent;
  /// Temperatures exist on firmware from 2018 on; older firmware leaves the bytes zero.
  std::uint8_t temperature_top_c = 0;
  std::uint8_t temperature_bottom_c = 0;
  std::array<char, 129> nmea{};  ///< NUL-terminated copy of the sentence (max 128 bytes)
  std::uint8_t nmea_length = 0;
  NmeaFix fix;

  std::string_view nmea_sentence() const { return {nmea.data(), nmea_length}; }
};

/// Decodes one 512-byte payload. kMalformed for a wrong size, a time beyond one hour or a PPS
/// code above 3. An empty or unparsable NMEA field is not an error (fix.kind == kNone/kOther).
Expected<PositionPacket> DecodePositionPacket(std::span<const std::uint8_t> payload);

/// Parses an NMEA sentence (with or without the leading '$' and the trailing checksum).
NmeaFix ParseNmea(std::string_view sentence);

}  // namespace msgraphs::drivers::velodyne
