// SPDX-License-Identifier: MIT
// Place clouds on the wire: the merge decision's bounded fallback (place_evidence.hpp). A robot
// whose decision about a peer is undecided asks that peer for its points around one place of
// the peer's map, and weighs them against its own free space.
//
// Request: "MSPQ" | format u8 (1) | from u16 | to u16 | place u32 | centre x, y f32 | radius f32
//   | CRC-32 -> 33 bytes: robot `from` asks robot `to` for its points within `radius_m` of
//   `centre_m` (to's map frame). `place` is the requester's number for it, echoed in the answer.
// Cloud: "MSPC" | format u8 (1) | robot u16 | to u16 | place u32 | centre x, y f32 | floor z f32
//   | step f32 | points u32 | points as i8 x3 in units of `step`, relative to (centre, floor)
//   | CRC-32: 3 bytes a point (+-127 steps: the sender picks the step from the radius).
// Decoding rejects short or trailing bytes, bad magic, unknown formats, CRC mismatches, equal or
// zero robot ids, non-finite or implausible geometry and more points than the receiver holds,
// each with a reason. Encoding and decoding allocate nothing.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"

namespace msgraphs::core {

struct PlaceRequest {
  std::uint16_t from = 0, to = 0;
  std::uint32_t place = 0;
  Eigen::Vector2f centre_m = Eigen::Vector2f::Zero();  ///< the addressee's map frame
  float radius_m = 0;
};
inline constexpr std::size_t kPlaceRequestBytes = 33;
/// A request's radius is at most this (the cloud's 8-bit units then stay within 10 cm).
inline constexpr float kMaxPlaceRadiusM = 12.7f;
Expected<std::size_t> EncodePlaceRequest(const PlaceRequest& request, std::span<std::uint8_t> out);
Expected<PlaceRequest> DecodePlaceRequest(std::span<const std::uint8_t> bytes);

struct PlaceCloudHeader {
  std::uint16_t robot = 0;  ///< the sender
  std::uint16_t to = 0;     ///< the requester
  std::uint32_t place = 0;
  Eigen::Vector2f centre_m = Eigen::Vector2f::Zero();  ///< the sender's map frame
  float floor_z_m = 0;                                 ///< the sender's floor in its map frame
  float step_m = 0.05f;
};

/// The step that fits points within `radius_m` of the centre (and as high above the floor)
/// into +-127 units, in whole centimetres.
float PlaceCloudStep(float radius_m);
std::size_t PlaceCloudEncodedSize(std::size_t points);
/// `points` relative to (centre, floor). kInvalidArgument when one does not fit the step.
Expected<std::size_t> EncodePlaceCloud(const PlaceCloudHeader& header,
                                       std::span<const Eigen::Vector3f> points,
                                       std::span<std::uint8_t> out);
/// Points relative to (centre, floor) into `points` (its capacity is the receiver's limit).
Expected<PlaceCloudHeader> DecodePlaceCloud(std::span<const std::uint8_t> bytes,
                                            BoundedVector<Eigen::Vector3f>& points);
/// Sender, addressee and place of a cloud message, unchecked (no CRC, no body): for a transport
/// that addresses the sample before the receiver decodes it.
Expected<PlaceCloudHeader> PeekPlaceCloudHeader(std::span<const std::uint8_t> bytes);

}  // namespace msgraphs::core
