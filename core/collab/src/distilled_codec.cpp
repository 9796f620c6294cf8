// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/distilled_codec.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <cstring>

#include "msgraphs/base/byte_order.hpp"
#include "msgraphs/base/crc32.hpp"

namespace msgraphs::core {
namespace {

constexpr std::uint8_t kFormat = 1;
constexpr std::uint8_t kMagic[4] = {'M', 'S', 'D', 'G'};

class Writer {
 public:
  explicit Writer(std::span<std::uint8_t> out) : out_(out) {}
  void U8(std::uint8_t v) { out_[pos_++] = v; }
  void U16(std::uint16_t v) {
    WriteU16Le(&out_[pos_], v);
    pos_ += 2;
  }
  void U32(std::uint32_t v) {
    WriteU32Le(&out_[pos_], v);
    pos_ += 4;
  }
  void F32(double v) {
    const auto f = static_cast<float>(v);
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    U32(u);
  }
  std::size_t pos() const { return pos_; }

 private:
  std::span<std::uint8_t> out_;
  std::size_t pos_ = 0;
};

class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> in) : in_(in) {}
  bool Has(std::size_t n) const { return pos_ + n <= in_.size(); }
  std::uint8_t U8() { return in_[pos_++]; }
  std::uint16_t U16() {
    const std::uint16_t v = ReadU16Le(&in_[pos_]);
    pos_ += 2;
    return v;
  }
  std::uint32_t U32() {
    const std::uint32_t v = ReadU32Le(&in_[pos_]);
    pos_ += 4;
    return v;
  }
  double F32() {
    const std::uint32_t u = U32();
    float f;
    std::memcpy(&f, &u, 4);
    return static_cast<double>(f);
  }
  std::size_t pos() const { return pos_; }

 private:
  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
};

std::size_t CountWalls(const DistilledGraph& g, std::uint32_t since) {
  std::size_t n = 0;
  for (const DistilledWall& w : g.walls) n += w.version > since ? 1u : 0u;
  return n;
}
std::size_t CountRooms(const DistilledGraph& g, std::uint32_t since) {
  std::size_t n = 0;
  for (const DistilledRoom& r : g.rooms) n += r.version > since ? 1u : 0u;
  return n;
}

Error Malformed(const char* why) { return Error{Errc::kMalformed, why}; }

}  // namespace

std::size_t DistilledEncodedSize(const DistilledGraph& graph, std::uint32_t since) {
  return kDistilledHeaderBytes + (graph.has_floor ? kDistilledFloorBytes : 0u) +
         CountWalls(graph, since) * kDistilledWallBytes +
         CountRooms(graph, since) * kDistilledRoomBytes + 4u;
}

Expected<std::size_t> EncodeDistilled(const DistilledGraph& g,
                                      std::uint32_t since,
                                      std::span<std::uint8_t> out) {
  const std::size_t walls = CountWalls(g, since), rooms = CountRooms(g, since);
  if (walls > 0xFFFF || rooms > 0xFFFF)
    return Error{Errc::kCapacityExceeded, "distilled graph: too many elements"};
  const std::size_t size = DistilledEncodedSize(g, since);
  if (size > out.size())
    return Error{Errc::kCapacityExceeded, "distilled graph: output buffer too small"};
  Writer w(out);
  for (std::uint8_t m : kMagic) w.U8(m);
  w.U8(kFormat);
  w.U8(g.has_floor ? 1u : 0u);
  w.U16(g.robot);
  w.U32(g.version);
  w.U32(since);
  w.U16(static_cast<std::uint16_t>(walls));
  w.U16(static_cast<std::uint16_t>(rooms));
  if (g.has_floor) {
    w.F32(g.floor_centre.x());
    w.F32(g.floor_centre.y());
    w.F32(static_cast<float>(g.floor_z_m));
  }
  for (const DistilledWall& x : g.walls) {
    if (x.version <= since) continue;
    w.U32(x.id);
    w.U32(x.version);
    for (int i = 0; i < 3; ++i) w.F32(x.normal[i]);
    w.F32(x.d);
    const Eigen::Matrix3d& c = x.covariance;
    for (double v : {c(0, 0), c(0, 1), c(0, 2), c(1, 1), c(1, 2), c(2, 2)}) w.F32(v);
    w.F32(x.a.x());
    w.F32(x.a.y());
    w.F32(x.b.x());
    w.F32(x.b.y());
  }
  for (const DistilledRoom& r : g.rooms) {
    if (r.version <= since) continue;
    w.U32(r.id);
    w.U32(r.version);
    w.U8(static_cast<std::uint8_t>(r.shape));
    w.F32(r.centre.x());
    w.F32(r.centre.y());
    w.F32(r.yaw_rad);
    w.F32(r.size_x_m);
    w.F32(r.size_y_m);
    for (std::int32_t id : r.walls) w.U32(static_cast<std::uint32_t>(id));
  }
  w.U32(Crc32(out.first(w.pos())));
  return w.pos();
}

Expected<std::uint16_t> DistilledSender(std::span<const std::uint8_t> bytes) {
  constexpr std::size_t kRobotAt = 6;  // magic (4), format, flags
  if (bytes.size() < kDistilledHeaderBytes + 4)
    return Error{Errc::kMalformed, "distilled graph: shorter than its header"};
  if (std::memcmp(bytes.data(), kMagic, 4) != 0)
    return Error{Errc::kMalformed, "distilled graph: bad magic"};
  // Checked before the receiver files the message under a robot: garbage must not invent one.
  const std::size_t body = bytes.size() - 4;
  if (ReadU32Le(&bytes[body]) != Crc32(bytes.first(body)))
    return Error{Errc::kChecksum, "distilled graph: CRC mismatch"};
  return ReadU16Le(&bytes[kRobotAt]);
}

Expected<DistilledDelta> DecodeDistilled(std::span<const std::uint8_t> bytes,
                                         DistilledGraph& out,
                                         const DistilledGraph* known) {
  out.walls.clear();
  out.rooms.clear();
  out.has_floor = false;
  if (bytes.size() < kDistilledHeaderBytes + 4)
    return Malformed("distilled graph: shorter than a header");
  const std::size_t body = bytes.size() - 4;
  if (ReadU32Le(&bytes[body]) != Crc32(bytes.first(body)))
    return Error{Errc::kChecksum, "distilled graph: CRC mismatch"};
  Reader r(bytes.first(body));
  for (std::uint8_t m : kMagic) {
    if (r.U8() != m) return Malformed("distilled graph: bad magic");
  }
  if (r.U8() != kFormat)
    return Error{Errc::kUnsupported, "distilled graph: unknown format version"};
  const std::uint8_t flags = r.U8();
  if ((flags & ~1u) != 0) return Malformed("distilled graph: unknown flags");
  out.robot = r.U16();
  out.version = r.U32();
  DistilledDelta delta;
  delta.since = r.U32();
  const std::size_t walls = r.U16(), rooms = r.U16();
  if (delta.since >= out.version && (walls > 0 || rooms > 0))
    return Malformed("distilled graph: elements newer than the graph");
  const std::size_t expected = kDistilledHeaderBytes +
                               ((flags & 1u) != 0 ? kDistilledFloorBytes : 0u) +
                               walls * kDistilledWallBytes + rooms * kDistilledRoomBytes;
  if (expected != body)
    return Malformed("distilled graph: length does not match the element counts");
  if (walls > out.walls.capacity() || rooms > out.rooms.capacity()) {
    return Error{Errc::kCapacityExceeded, "distilled graph: more elements than the receiver holds"};
  }
  if ((flags & 1u) != 0) {
    out.has_floor = true;
    out.floor_centre.x() = r.F32();
    out.floor_centre.y() = r.F32();
    out.floor_z_m = r.F32();
    if (!out.floor_centre.allFinite() || !std::isfinite(out.floor_z_m))
      return Malformed("distilled graph: floor not finite");
  }
  for (std::size_t i = 0; i < walls; ++i) {
    DistilledWall w;
    w.id = r.U32();
    w.version = r.U32();
    for (int k = 0; k < 3; ++k) w.normal[k] = r.F32();
    w.d = r.F32();
    double c[6];
    for (double& v : c) v = r.F32();
    w.covariance << c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5];
    w.a.x() = r.F32();
    w.a.y() = r.F32();
    w.b.x() = r.F32();
    w.b.y() = r.F32();
    if (!w.normal.allFinite() || !std::isfinite(w.d) || !w.covariance.allFinite() ||
        !w.a.allFinite() || !w.b.allFinite()) {
      return Malformed("distilled graph: wall not finite");
    }
    if (std::fabs(w.normal.norm() - 1.0) > 1e-3)
      return Malformed("distilled graph: wall normal not unit");
    if (w.version <= delta.since || w.version > out.version)
      return Malformed("distilled graph: wall version out of range");
    if (Eigen::LLT<Eigen::Matrix3d>(w.covariance).info() != Eigen::Success) {
      return Malformed("distilled graph: wall covariance not positive definite");
    }
    w.normal.normalize();
    out.walls.push_back(w);
  }
  for (std::size_t i = 0; i < rooms; ++i) {
    DistilledRoom room;
    room.id = r.U32();
    room.version = r.U32();
    const std::uint8_t shape = r.U8();
    if (shape > static_cast<std::uint8_t>(RoomShape::kCorridor))
      return Malformed("distilled graph: unknown room shape");
    room.shape = static_cast<RoomShape>(shape);
    room.centre.x() = r.F32();
    room.centre.y() = r.F32();
    room.yaw_rad = r.F32();
    room.size_x_m = r.F32();
    room.size_y_m = r.F32();
    for (std::int32_t& id : room.walls) id = static_cast<std::int32_t>(r.U32());
    if (!room.centre.allFinite() || !std::isfinite(room.yaw_rad) || !std::isfinite(room.size_x_m) ||
        !std::isfinite(room.size_y_m) || room.size_x_m < 0 || room.size_y_m < 0) {
      return Malformed("distilled graph: room not finite");
    }
    if (room.version <= delta.since || room.version > out.version)
      return Malformed("distilled graph: room version out of range");
    const int needed = room.shape == RoomShape::kFourWall ? 4 : 2;
    for (int k = 0; k < 4; ++k) {
      const std::int32_t id = room.walls[static_cast<std::size_t>(k)];
      if (k >= needed) {
        if (id != -1) return Malformed("distilled graph: corridor with a second wall pair");
        continue;
      }
      if (id < 0) return Malformed("distilled graph: room wall missing");
      const auto uid = static_cast<std::uint32_t>(id);
      if (out.FindWall(uid) == nullptr && (known == nullptr || known->FindWall(uid) == nullptr)) {
        return Malformed("distilled graph: room refers to an unknown wall");
      }
    }
    out.rooms.push_back(room);
  }
  return delta;
}

namespace {

// Inserts or replaces (when newer) the element with the same id.
template <typename T>
bool Upsert(BoundedVector<T>& copy, const T& element) {
  for (T& c : copy) {
    if (c.id != element.id) continue;
    if (element.version >= c.version) c = element;
    return true;
  }
  return copy.try_push_back(element);
}

}  // namespace

Status ApplyDistilled(const DistilledGraph& delta, DistilledGraph& copy) {
  copy.robot = delta.robot;
  copy.version = std::max(copy.version, delta.version);
  copy.has_floor = delta.has_floor || copy.has_floor;
  if (delta.has_floor) {
    copy.floor_centre = delta.floor_centre;
    copy.floor_z_m = delta.floor_z_m;
  }
  bool full = false;
  for (const DistilledWall& w : delta.walls) full = !Upsert(copy.walls, w) || full;
  for (const DistilledRoom& r : delta.rooms) full = !Upsert(copy.rooms, r) || full;
  if (full) return Error{Errc::kCapacityExceeded, "distilled copy: full; what fit was kept"};
  return Ok();
}

}  // namespace msgraphs::core
