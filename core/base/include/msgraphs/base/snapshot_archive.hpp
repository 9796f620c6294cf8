// SPDX-License-Identifier: MIT
// A state snapshot's bytes: one visitor per record writes it and reads it back, so the two can
// never disagree on a field (the reason a journal of inputs was preferred until now).
//
//   template <class Archive> void Io(Archive& ar, Node& n) { ar(n.stamp_s); ar(n.q, 4); }
//   (a matrix: ar(m.data(), m.size()))
//   SnapshotWriter w(buffer);  Io(w, node);   // w.failed(): the buffer was too small
//   SnapshotReader r(bytes);   Io(r, node);   // r.failed(): the bytes ran out
//
// Values are copied as the host holds them (byte order, IEEE doubles): a snapshot is read back
// by the program that wrote it, on the same machine, and checked by a version, the sizes of its
// records and a CRC (SnapshotHeader). Neither side allocates.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <type_traits>

namespace msgraphs {

class SnapshotWriter {
 public:
  static constexpr bool kLoading = false;
  explicit SnapshotWriter(std::span<std::uint8_t> out) : out_(out) {}

  template <typename T>
    requires std::is_trivially_copyable_v<T>
  void operator()(const T& value) {
    Bytes(&value, sizeof(T));
  }
  template <typename T>
    requires std::is_trivially_copyable_v<T>
  void operator()(const T* values, std::size_t count) {
    Bytes(values, sizeof(T) * count);
  }

  bool failed() const { return failed_; }
  std::size_t size() const { return pos_; }

 private:
  void Bytes(const void* p, std::size_t n) {
    if (failed_ || n > out_.size() - pos_) {
      failed_ = true;
      return;
    }
    std::memcpy(out_.data() + pos_, p, n);
    pos_ += n;
  }
  std::span<std::uint8_t> out_;
  std::size_t pos_ = 0;
  bool failed_ = false;
};

class SnapshotReader {
 public:
  static constexpr bool kLoading = true;
  explicit SnapshotReader(std::span<const std::uint8_t> in) : in_(in) {}

  template <typename T>
    requires std::is_trivially_copyable_v<T>
  void operator()(T& value) {
    Bytes(&value, sizeof(T));
  }
  template <typename T>
    requires std::is_trivially_copyable_v<T>
  void operator()(T* values, std::size_t count) {
    Bytes(values, sizeof(T) * count);
  }

  bool failed() const { return failed_; }
  std::size_t size() const { return pos_; }
  std::size_t remaining() const { return in_.size() - pos_; }
  // A reader that found a value out of range marks itself failed: what follows is not read.
  void Fail() { failed_ = true; }

 private:
  void Bytes(void* p, std::size_t n) {
    if (failed_ || n > in_.size() - pos_) {
      failed_ = true;
      std::memset(p, 0, n);
      return;
    }
    std::memcpy(p, in_.data() + pos_, n);
    pos_ += n;
  }
  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
  bool failed_ = false;
};

// A bool as one byte, 0 or 1 (read: anything else is 1).
template <class Archive>
void IoBool(Archive& ar, bool& b) {
  std::uint8_t v = b ? 1 : 0;
  ar(v);
  if constexpr (Archive::kLoading) b = v != 0;
}

// An enum as its underlying byte; a value at or past `count` fails the reader.
template <class Archive, typename E>
void IoEnum(Archive& ar, E& e, std::uint8_t count) {
  auto v = static_cast<std::uint8_t>(e);
  ar(v);
  if constexpr (Archive::kLoading) {
    if (v >= count) ar.Fail();
    e = static_cast<E>(v);
  }
}

// A count of entries; above `max` fails the reader (and reads as 0).
template <class Archive>
void IoCount(Archive& ar, std::size_t& n, std::size_t max) {
  auto v = static_cast<std::uint64_t>(n);
  ar(v);
  if constexpr (Archive::kLoading) {
    n = v <= max ? static_cast<std::size_t>(v) : 0;
    if (v > max) ar.Fail();
  }
}

// A store sized at Init: its size is written, and a reader of a store of another size fails.
template <class Archive>
void IoSameSize(Archive& ar, std::size_t size) {
  auto v = static_cast<std::uint64_t>(size);
  ar(v);
  if constexpr (Archive::kLoading) {
    if (v != size) ar.Fail();
  }
}

}  // namespace msgraphs
