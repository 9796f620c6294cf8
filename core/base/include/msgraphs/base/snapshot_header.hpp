// SPDX-License-Identifier: MIT
// A snapshot's header (the S-Graph's, the mapper's): magic (8 bytes), version u32, payload
// length u64, CRC-32 of the payload, then the payload. Host byte order, as the archive.
// The CRC may be left for later (SnapshotSeal::kLater) and written by SealSnapshotHeader on
// another thread: a 52 MB snapshot's CRC is 15 ms that the thread that copied the state out
// need not pay.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "msgraphs/base/crc32.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/snapshot_archive.hpp"

namespace msgraphs {

constexpr std::size_t kSnapshotHeaderBytes = 8 + 4 + 8 + 4;
using SnapshotMagic = std::array<std::uint8_t, 8>;

/// kNow: the header carries the payload's CRC. kLater: a zero in its place until
/// SealSnapshotHeader; until then a load refuses it as any snapshot whose CRC does not check.
enum class SnapshotSeal : std::uint8_t { kNow, kLater };

/// Writes the header for the payload that follows it in `out`; returns the whole length.
inline std::size_t WriteSnapshotHeader(std::span<std::uint8_t> out, const SnapshotMagic& magic,
                                       std::uint32_t version, std::size_t payload_bytes,
                                       SnapshotSeal seal = SnapshotSeal::kNow) {
  const auto payload = std::span<const std::uint8_t>(out).subspan(kSnapshotHeaderBytes, payload_bytes);
  SnapshotWriter h(out.first(kSnapshotHeaderBytes));
  h(magic.data(), magic.size());
  h(version);
  h(static_cast<std::uint64_t>(payload.size()));
  h(seal == SnapshotSeal::kNow ? Crc32(payload) : std::uint32_t{0});
  return kSnapshotHeaderBytes + payload.size();
}

namespace detail {
struct SnapshotHeaderFields {
  SnapshotMagic magic{};
  std::uint32_t version = 0;
  std::uint64_t payload_bytes = 0;
  std::uint32_t crc = 0;
};

/// The header's fields when the whole header is within `in`; nullopt otherwise. After it,
/// `in.size() - kSnapshotHeaderBytes` cannot wrap.
inline std::optional<SnapshotHeaderFields> ReadSnapshotHeader(std::span<const std::uint8_t> in) {
  SnapshotReader h(in);
  SnapshotHeaderFields f;
  h(f.magic.data(), f.magic.size());
  h(f.version);
  h(f.payload_bytes);
  h(f.crc);
  if (h.failed()) return std::nullopt;
  return f;
}
}  // namespace detail

/// The payload length a header of `magic`'s kind gives, when the header and that payload are
/// within `snapshot`; kInvalidArgument otherwise. Reads only.
inline Expected<std::size_t> SnapshotPayloadBytes(std::span<const std::uint8_t> snapshot, const SnapshotMagic& magic) {
  const auto f = detail::ReadSnapshotHeader(snapshot);
  if (!f || f->magic != magic || f->payload_bytes > snapshot.size() - kSnapshotHeaderBytes)
    return Error{Errc::kInvalidArgument, "snapshot: not a whole snapshot of this kind"};
  return static_cast<std::size_t>(f->payload_bytes);
}

/// Writes the CRC of a snapshot written with SnapshotSeal::kLater (`snapshot`: its header and
/// at least its payload, as Save returned them). kInvalidArgument, changing nothing, when the
/// header is not `magic`'s or its payload runs past `snapshot`.
inline Status SealSnapshotHeader(std::span<std::uint8_t> snapshot, const SnapshotMagic& magic) {
  auto bytes = SnapshotPayloadBytes(snapshot, magic);
  if (!bytes) return bytes.error();
  const auto payload = std::span<const std::uint8_t>(snapshot).subspan(kSnapshotHeaderBytes, *bytes);
  SnapshotWriter crc(snapshot.subspan(kSnapshotHeaderBytes - 4, 4));
  crc(Crc32(payload));
  return Ok();
}

/// The payload of a whole snapshot of this kind and version; kInvalidArgument otherwise.
inline Expected<std::span<const std::uint8_t>> SnapshotPayload(std::span<const std::uint8_t> in,
                                                               const SnapshotMagic& magic,
                                                               std::uint32_t version) {
  const auto f = detail::ReadSnapshotHeader(in);
  if (!f || f->magic != magic) return Error{Errc::kInvalidArgument, "snapshot: not one of this kind"};
  if (f->version != version) return Error{Errc::kInvalidArgument, "snapshot: another version"};
  if (f->payload_bytes != in.size() - kSnapshotHeaderBytes)
    return Error{Errc::kInvalidArgument, "snapshot: truncated or overlong"};
  const std::span<const std::uint8_t> payload = in.subspan(kSnapshotHeaderBytes);
  if (Crc32(payload) != f->crc) return Error{Errc::kInvalidArgument, "snapshot: CRC mismatch"};
  return payload;
}

}  // namespace msgraphs
