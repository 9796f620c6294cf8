// SPDX-License-Identifier: MIT
// Graph keys. Every node of every robot's S-Graph is named by the robot that created it, the
// layer it lives in and an index within that robot and layer, so graphs of several robots can
// be joined without renumbering (the idea of GTSAM's Symbol('a', i), with a real robot id).
#pragma once

#include <compare>
#include <cstddef>
#include <cstdint>
#include <functional>

namespace msgraphs {

/// A robot's identity in the fleet. 0 is reserved as "no robot".
struct RobotId {
  std::uint16_t value = 0;
  constexpr auto operator<=>(const RobotId&) const = default;
  constexpr bool valid() const { return value != 0; }
};

/// The S-Graph layer a node belongs to.
enum class NodeKind : std::uint8_t {
  kOrigin = 0,    ///< the robot's map origin (one per robot; a free node in other robots' graphs)
  kKeyframe = 1,
  kWall = 2,
  kRoom = 3,
  kFloor = 4,
};
inline constexpr std::uint8_t kNumNodeKinds = 5;

struct NodeKey {
  RobotId robot_id;
  NodeKind kind = NodeKind::kKeyframe;
  std::uint32_t index = 0;

  constexpr auto operator<=>(const NodeKey&) const = default;

  /// Packs into 56 bits: robot (16) | kind (8) | index (32). Stable across builds and
  /// architectures; used on the wire and in checkpoints.
  constexpr std::uint64_t Packed() const {
    return (std::uint64_t{robot_id.value} << 40) | (std::uint64_t{static_cast<std::uint8_t>(kind)} << 32) |
           std::uint64_t{index};
  }
  /// Inverse of Packed(). Returns false (and leaves *out alone) for bits no key produces.
  static constexpr bool FromPacked(std::uint64_t packed, NodeKey* out) {
    if ((packed >> 56) != 0) return false;
    const auto kind_bits = static_cast<std::uint8_t>((packed >> 32) & 0xFFu);
    if (kind_bits >= kNumNodeKinds) return false;
    *out = NodeKey{RobotId{static_cast<std::uint16_t>(packed >> 40)}, static_cast<NodeKind>(kind_bits),
                   static_cast<std::uint32_t>(packed & 0xFFFFFFFFu)};
    return true;
  }
};

}  // namespace msgraphs

template <>
struct std::hash<msgraphs::NodeKey> {
  std::size_t operator()(const msgraphs::NodeKey& key) const noexcept {
    return std::hash<std::uint64_t>{}(key.Packed());
  }
};
