// SPDX-License-Identifier: MIT
// The checkpoint's snapshot file (snapshot.N.bin, docs/runtime.md "Checkpoint and restart"):
// the mapper's snapshot, the session's peer state as the messages that rebuild it, and where
// the robot's inputs stood, checked whole by one CRC.
//
// Little-endian:
//   "MSGRAPHS-SNAPSHOT v1\n" (21 bytes) | robot u16 | generation u64 | mapper settings CRC u32 |
//   last scan end f64 | last odometry stamp f64 | last odometry pose x y z qx qy qz qw f64 |
//   journal messages u64 | mapper bytes u64 | the mapper's snapshot (LocalMapper::Save) |
//   session messages u32 | each: type u8, length u32, bytes | CRC-32 of everything before u32
//
// "journal messages": how many peer messages journal.N (the generation's journal) already held
// when the session was exported: the session part holds them, and replay skips exactly those.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/collab/collab_session.hpp"

namespace msgraphs::runtime {

/// Where the robot's inputs stood at the snapshot, and what it belongs to.
struct CheckpointMeta {
  std::uint16_t robot = 0;
  std::uint64_t generation = 0;
  std::uint32_t mapper_settings_crc = 0;
  double last_scan_end_s = -1, last_odometry_s = -1;
  Eigen::Isometry3d T_odom_last = Eigen::Isometry3d::Identity();
  std::uint64_t journal_messages = 0;
};

inline constexpr std::size_t kCheckpointHeadBytes = 21 + 2 + 8 + 4 + 8 + 8 + 56 + 8 + 8;

/// Writes the head (everything before the mapper's bytes) into `out` (kCheckpointHeadBytes).
void WriteCheckpointHead(const CheckpointMeta& meta, std::uint64_t mapper_bytes,
                         std::span<std::uint8_t, kCheckpointHeadBytes> out);
/// Appends one session message (type, length, bytes) to `out`.
void AppendSessionMessage(core::CollabMessageType type, std::span<const std::uint8_t> bytes,
                          std::vector<std::uint8_t>& out);

struct ParsedCheckpoint {
  CheckpointMeta meta;
  std::span<const std::uint8_t> mapper;   ///< LocalMapper::Load's bytes
  std::span<const std::uint8_t> session;  ///< the session messages (ForEachSessionMessage)
  std::uint32_t session_messages = 0;
};

/// Checks a whole file (magic, lengths, every session message's framing and type, the CRC,
/// finite numbers) before anything is used: kInvalidArgument with a reason otherwise. Another
/// robot's file is kInvalidConfig (the folder belongs to one robot). Allocates nothing.
Expected<ParsedCheckpoint> ParseCheckpoint(std::span<const std::uint8_t> file, std::uint16_t robot);

/// Calls `fn(type, bytes)` for each session message of a parsed file, in order.
template <class Fn>
void ForEachSessionMessage(const ParsedCheckpoint& parsed, Fn&& fn) {
  std::span<const std::uint8_t> rest = parsed.session;
  for (std::uint32_t i = 0; i < parsed.session_messages; ++i) {
    const auto type = static_cast<core::CollabMessageType>(rest[0]);
    const std::uint32_t length = static_cast<std::uint32_t>(rest[1]) |
                                 static_cast<std::uint32_t>(rest[2]) << 8 |
                                 static_cast<std::uint32_t>(rest[3]) << 16 |
                                 static_cast<std::uint32_t>(rest[4]) << 24;
    fn(type, rest.subspan(5, length));
    rest = rest.subspan(5 + length);
  }
}

/// The generation a checkpoint folder entry belongs to: "journal.bin" is 0, "journal.N.bin"
/// and "snapshot.N.bin" are N (1..2^63); false for anything else (left alone).
bool CheckpointGeneration(const std::string& name, bool& is_snapshot, std::uint64_t& generation);

}  // namespace msgraphs::runtime
