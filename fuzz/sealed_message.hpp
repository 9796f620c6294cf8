// SPDX-License-Identifier: MIT
// For the collaboration fuzz targets: the fuzzer's bytes as a message body with the correct
// CRC-32 appended, so that the parsers past the checksum run (a wrong CRC alone is rejected at
// once).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "msgraphs/base/byte_order.hpp"
#include "msgraphs/base/crc32.hpp"

inline std::vector<std::uint8_t> SealedMessage(std::span<const std::uint8_t> body) {
  std::vector<std::uint8_t> message(body.begin(), body.end());
  message.resize(message.size() + 4);
  msgraphs::WriteU32Le(message.data() + body.size(),
                       msgraphs::Crc32(std::span(message.data(), body.size())));
  return message;
}
