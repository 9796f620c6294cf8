// SPDX-License-Identifier: MIT
// Room descriptors and room clouds on the wire (little-endian, CRC-32 at the end).
//
// Descriptor: "MSRD" | format u8 (2) | robot u16 | room u32 | version u32 | rings u8 | sectors u8
//   | max radius f32 | height step u8 (cm) | cells u8 x rings x sectors (heights in steps: 1 cm
//   up to 2.55 m, the step growing with the room's tallest cell, up to 8 cm) -> 1.2 kB for
//   20 x 60 instead of 4.8 kB of f32. Format 1 (no step byte, 1 cm) is still decoded.
// Cloud: "MSRC" | format u8 | encoding u8 | robot u16 | room u32 | version u32 | step f32 |
//   points u32 | points as f32 x3 (encoding 0), as i16 x3 in units of `step` (encoding 1: 6
//   bytes a point, +-327 m at 1 cm) or as i8 x3 in units of `step` (encoding 2: 3 bytes a point,
//   +-6.35 m at 5 cm).
// Cloud request: "MSRQ" | format u8 | from u16 | to u16 | room u32 | version u32 -> 21 bytes
//   with the CRC: robot `from` asks robot `to` for the cloud of `room` at `version`.
// Decoding rejects short or trailing bytes, bad magic, unknown formats or encodings, CRC
// mismatches, sizes beyond the receiver's capacity, and non-finite values, with a reason.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/descriptors/scan_context.hpp"

namespace msgraphs::core {

struct RoomDescriptorHeader {
  std::uint16_t robot = 0;
  std::uint32_t room = 0, version = 0;
};

std::size_t RoomDescriptorEncodedSize(const ScanContext& descriptor);
std::size_t RoomDescriptorEncodedSize(int rings, int sectors);
Expected<std::size_t> EncodeRoomDescriptor(const RoomDescriptorHeader& header,
                                           const ScanContext& descriptor,
                                           std::span<std::uint8_t> out);
Expected<RoomDescriptorHeader> DecodeRoomDescriptor(std::span<const std::uint8_t> bytes,
                                                    ScanContext& descriptor);
/// The header fields only, unchecked (no CRC, no body): for a transport that files the message
/// under its robot and room before the receiver decodes it. kMalformed when too short or the
/// magic is wrong.
Expected<RoomDescriptorHeader> PeekRoomDescriptorHeader(std::span<const std::uint8_t> bytes);

/// kQuantised8: 3 bytes a point, +-127 steps (+-6.35 m at 5 cm: a room cloud in its room frame,
/// cropped to the walls plus 0.3 m, fits unless the room is wider than 12 m).
enum class CloudEncoding : std::uint8_t { kFloat32 = 0, kQuantised16 = 1, kQuantised8 = 2 };

struct RoomCloudHeader {
  std::uint16_t robot = 0;
  std::uint32_t room = 0, version = 0;
  CloudEncoding encoding = CloudEncoding::kQuantised16;
  float step_m = 0.01f;  ///< quantisation step (kQuantised16)
};

std::size_t RoomCloudEncodedSize(CloudEncoding encoding, std::size_t points);
/// kInvalidArgument when a point does not fit the quantised range.
Expected<std::size_t> EncodeRoomCloud(const RoomCloudHeader& header,
                                      std::span<const Eigen::Vector3f> points,
                                      std::span<std::uint8_t> out);
Expected<RoomCloudHeader> DecodeRoomCloud(std::span<const std::uint8_t> bytes,
                                          BoundedVector<Eigen::Vector3f>& points);
/// Robot, room and version of a cloud message, unchecked (see PeekRoomDescriptorHeader).
Expected<RoomCloudHeader> PeekRoomCloudHeader(std::span<const std::uint8_t> bytes);

struct RoomCloudRequest {
  std::uint16_t from = 0, to = 0;
  std::uint32_t room = 0, version = 0;
};
inline constexpr std::size_t kRoomCloudRequestBytes = 21;
Expected<std::size_t> EncodeRoomCloudRequest(const RoomCloudRequest& request,
                                             std::span<std::uint8_t> out);
Expected<RoomCloudRequest> DecodeRoomCloudRequest(std::span<const std::uint8_t> bytes);

}  // namespace msgraphs::core
