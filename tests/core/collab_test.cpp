// SPDX-License-Identifier: MIT
// The multi-robot pieces: the distilled graph's wire encoding (round trip, deltas, every kind of
// malformed input), room descriptor and room cloud messages, the consistency check against a
// planted symmetric mismatch, fine alignment of two views of a room, and the collaborative
// graph recovering another robot's origin.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/base/byte_order.hpp"
#include "msgraphs/base/crc32.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/collab/feedback_gate.hpp"
#include "msgraphs/core/collab/distilled_codec.hpp"
#include "msgraphs/core/collab/distiller.hpp"
#include "msgraphs/core/collab/room_matcher.hpp"
#include "msgraphs/core/collab/room_messages.hpp"
#include "msgraphs/core/geometry/se3.hpp"
#include "msgraphs/core/graph/collaborative_graph.hpp"
#include "distilled_rooms.hpp"
#include "synthetic_clouds.hpp"

namespace msgraphs::core {
namespace {

Eigen::Isometry3d Planar(double x, double y, double yaw) { return test::PlanarPose(x, y, yaw); }
using test::AddRoom;

DistilledGraph SampleGraph() {
  DistilledGraph g;
  g.Init(16, 4);
  g.robot = 2;
  g.version = 5;
  g.has_floor = true;
  g.floor_centre = {1.5, -2.0};
  AddRoom(g, 10, 1, Planar(2, 3, 0.3), 3);
  AddRoom(g, 20, 2, Planar(9, 3, 0.3), 5);
  return g;
}

TEST(DistilledCodec, RoundTripsAndSendsOnlyWhatChanged) {
  const DistilledGraph g = SampleGraph();
  std::vector<std::uint8_t> buffer(4096);
  auto n = EncodeDistilled(g, 0, buffer);
  ASSERT_TRUE(n);
  EXPECT_EQ(*n, DistilledEncodedSize(g, 0));
  EXPECT_EQ(*n, kDistilledHeaderBytes + kDistilledFloorBytes + 8 * kDistilledWallBytes +
                    2 * kDistilledRoomBytes + 4);
  DistilledGraph out;
  out.Init(16, 4);
  auto delta = DecodeDistilled(std::span(buffer.data(), *n), out);
  ASSERT_TRUE(delta);
  EXPECT_EQ(delta->since, 0u);
  EXPECT_EQ(out.robot, 2);
  EXPECT_EQ(out.version, 5u);
  ASSERT_EQ(out.walls.size(), 8u);
  ASSERT_EQ(out.rooms.size(), 2u);
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(out.walls[i].id, g.walls[i].id);
    EXPECT_LT((out.walls[i].normal - g.walls[i].normal).norm(), 1e-6);
    EXPECT_NEAR(out.walls[i].d, g.walls[i].d, 1e-5);
    EXPECT_TRUE(out.walls[i].covariance.isApprox(g.walls[i].covariance, 1e-6));
  }
  EXPECT_EQ(out.rooms[1].walls, g.rooms[1].walls);
  EXPECT_NEAR(out.rooms[1].yaw_rad, 0.3, 1e-6);
  // Since version 3, only the second room and its walls travel; they may refer to known walls.
  auto d = EncodeDistilled(g, 3, buffer);
  ASSERT_TRUE(d);
  EXPECT_EQ(*d, kDistilledHeaderBytes + kDistilledFloorBytes + 4 * kDistilledWallBytes +
                    kDistilledRoomBytes + 4);
  DistilledGraph copy;
  copy.Init(16, 4);
  ASSERT_TRUE(ApplyDistilled(out, copy));
  DistilledGraph delta_only;
  delta_only.Init(16, 4);
  ASSERT_TRUE(DecodeDistilled(std::span(buffer.data(), *d), delta_only, &copy));
  EXPECT_EQ(delta_only.walls.size(), 4u);
  ASSERT_TRUE(ApplyDistilled(delta_only, copy));
  EXPECT_EQ(copy.walls.size(), 8u);  // upserted, not duplicated
  EXPECT_EQ(copy.rooms.size(), 2u);
  // Too small a buffer is a clear error.
  EXPECT_EQ(EncodeDistilled(g, 0, std::span(buffer.data(), 100)).error().code,
            Errc::kCapacityExceeded);
}

// distilled_codec.hpp: "Nothing allocates." The receiver's copies are sized by Init; decoding
// the full message and a delta, applying both, and refusing a corrupted message are counted.
TEST(DistilledCodec, DecodingApplyingAndRefusingAllocateNothing) {
  const DistilledGraph g = SampleGraph();
  std::vector<std::uint8_t> full(4096), delta(4096);
  const auto n = EncodeDistilled(g, 0, full);
  const auto d = EncodeDistilled(g, 3, delta);
  ASSERT_TRUE(n);
  ASSERT_TRUE(d);
  DistilledGraph out, copy, delta_only;
  out.Init(16, 4);
  copy.Init(16, 4);
  delta_only.Init(16, 4);
  std::vector<std::uint8_t> corrupted(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(*n));
  corrupted[kDistilledHeaderBytes + 3] ^= 0x40u;
  std::uint64_t allocations = 0;
  bool decoded = false, applied = false, decoded_delta = false, applied_delta = false, refused = false;
  {
    test::AllocationScope scope;
    decoded = DecodeDistilled(std::span(full.data(), *n), out).has_value();
    applied = ApplyDistilled(out, copy).has_value();
    decoded_delta = DecodeDistilled(std::span(delta.data(), *d), delta_only, &copy).has_value();
    applied_delta = ApplyDistilled(delta_only, copy).has_value();
    refused = !DecodeDistilled(corrupted, out).has_value();
    allocations = scope.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_TRUE(decoded && applied && decoded_delta && applied_delta && refused);
  EXPECT_EQ(copy.walls.size(), 8u);
  EXPECT_EQ(copy.rooms.size(), 2u);
}

// Writes a little-endian u32 into a message at `at`, checked against its size (a raw pointer
// into a vector that -O3 has inlined made GCC 12 warn of a write past a zero-sized region).
void PutU32(std::vector<std::uint8_t>& m, std::size_t at, std::uint32_t v) {
  ASSERT_LE(at + 4, m.size());
  std::uint8_t bytes[4];
  WriteU32Le(bytes, v);
  std::copy(bytes, bytes + 4, m.begin() + static_cast<std::ptrdiff_t>(at));
}

// Re-seals a tampered message so that the CRC passes and the parser itself must object.
void Reseal(std::vector<std::uint8_t>& m) {
  PutU32(m, m.size() - 4, Crc32(std::span(m.data(), m.size() - 4)));
}

TEST(DistilledCodec, RejectsMalformedInputWithAReason) {
  const DistilledGraph g = SampleGraph();
  std::vector<std::uint8_t> good(4096);
  good.resize(*EncodeDistilled(g, 0, good));
  DistilledGraph out;
  out.Init(16, 4);
  auto expect = [&](std::vector<std::uint8_t> m, Errc code) {
    auto r = DecodeDistilled(m, out);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, code) << r.error().detail;
  };
  expect({}, Errc::kMalformed);
  expect(std::vector<std::uint8_t>(good.begin(), good.begin() + 30), Errc::kChecksum);  // truncated
  auto flipped = good;
  flipped[40] ^= 0x10;
  expect(flipped, Errc::kChecksum);
  auto magic = good;
  magic[0] = 'X';
  Reseal(magic);
  expect(magic, Errc::kMalformed);
  auto format = good;
  format[4] = 9;
  Reseal(format);
  expect(format, Errc::kUnsupported);
  auto count = good;
  count[16] = 9;  // nine walls claimed
  Reseal(count);
  expect(count, Errc::kMalformed);
  auto normal = good;
  const float two = 2.0f;
  std::uint32_t bits;
  std::memcpy(&bits, &two, 4);
  PutU32(normal, 20 + kDistilledFloorBytes + 8, bits);  // first wall's normal x
  Reseal(normal);
  expect(normal, Errc::kMalformed);
  auto nan = good;
  const float q = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&bits, &q, 4);
  PutU32(nan, 20 + kDistilledFloorBytes + 8 + 12, bits);  // first wall's d
  Reseal(nan);
  expect(nan, Errc::kMalformed);
  auto covariance = good;
  const float negative = -1.0f;
  std::memcpy(&bits, &negative, 4);
  PutU32(covariance, 20 + kDistilledFloorBytes + 8 + 16, bits);  // first wall's covariance xx
  Reseal(covariance);
  expect(covariance, Errc::kMalformed);
  auto unknown_wall = good;
  const std::size_t room0 = 20 + kDistilledFloorBytes + 8 * kDistilledWallBytes;
  PutU32(unknown_wall, room0 + 29, 999);  // the first room's first wall id
  Reseal(unknown_wall);
  expect(unknown_wall, Errc::kMalformed);
  auto shape = good;
  shape[room0 + 8] = 7;
  Reseal(shape);
  expect(shape, Errc::kMalformed);
  // More elements than the receiver holds.
  DistilledGraph small;
  small.Init(2, 1);
  auto r = DecodeDistilled(good, small);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, Errc::kCapacityExceeded);
  // And the intact message still decodes.
  EXPECT_TRUE(DecodeDistilled(good, out));
}

TEST(RoomMessages, DescriptorsAndCloudsRoundTripCompactly) {
  const auto cloud = test::BoxRoom(6, 4, 2.4, 3000, 0.01, 3,
                                   Eigen::Isometry3d(Eigen::Translation3d(-3, -2, 0)), false);
  ScanContext sc;
  ASSERT_TRUE(sc.Build(cloud, {20, 60, 12.0f, 0.0f}));
  std::vector<std::uint8_t> buffer(1 << 20);
  auto n = EncodeRoomDescriptor({2, 7, 4}, sc, buffer);
  ASSERT_TRUE(n);
  EXPECT_EQ(*n, 22u + 20u * 60u + 4u);
  ScanContext back;
  auto h = DecodeRoomDescriptor(std::span(buffer.data(), *n), back);
  ASSERT_TRUE(h);
  EXPECT_EQ(h->room, 7u);
  for (int r = 0; r < 20; ++r) {
    for (int s = 0; s < 60; ++s) EXPECT_NEAR(back.cell(r, s), sc.cell(r, s), 0.0051f);
  }
  EXPECT_LT(ScanContextDistance(sc, back)->distance, 0.01f);
  // A 5 m high room: its heights go in 2 cm steps (5 m / 255 rounded up), within 1 cm.
  const auto tall = test::BoxRoom(6, 4, 5.0, 3000, 0.01, 4, Eigen::Isometry3d(Eigen::Translation3d(-3, -2, 0)), false);
  ASSERT_TRUE(sc.Build(tall, {20, 60, 12.0f, 0.0f}));
  n = EncodeRoomDescriptor({2, 8, 1}, sc, buffer);
  ASSERT_TRUE(n);
  ASSERT_TRUE(DecodeRoomDescriptor(std::span(buffer.data(), *n), back));
  float tallest = 0;
  for (int r = 0; r < 20; ++r) {
    for (int s = 0; s < 60; ++s) {
      EXPECT_NEAR(back.cell(r, s), sc.cell(r, s), 0.0101f);
      tallest = std::max(tallest, back.cell(r, s));
    }
  }
  EXPECT_GT(tallest, 4.9f);
  // Clouds: float and 1 cm quantised (half the bytes, within 5 mm).
  BoundedVector<Eigen::Vector3f> points(4000);
  for (CloudEncoding e : {CloudEncoding::kFloat32, CloudEncoding::kQuantised16}) {
    auto c = EncodeRoomCloud({2, 7, 4, e, 0.01f}, cloud, buffer);
    ASSERT_TRUE(c);
    EXPECT_EQ(*c, RoomCloudEncodedSize(e, cloud.size()));
    ASSERT_TRUE(DecodeRoomCloud(std::span(buffer.data(), *c), points));
    ASSERT_EQ(points.size(), cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      EXPECT_LT((points[i] - cloud[i]).norm(), e == CloudEncoding::kFloat32 ? 1e-7f : 0.0087f);
    }
  }
  EXPECT_EQ(RoomCloudEncodedSize(CloudEncoding::kQuantised16, 1000) - 28, 6000u);
  // 8 bits at 5 cm: 3 bytes a point, within 2.5 cm per axis; a point beyond +-6.35 m is refused.
  {
    std::vector<Eigen::Vector3f> room;
    for (const Eigen::Vector3f& q : cloud) {
      if (q.cwiseAbs().maxCoeff() < 6.3f) room.push_back(q);
    }
    ASSERT_FALSE(room.empty());
    auto c8 = EncodeRoomCloud({2, 7, 4, CloudEncoding::kQuantised8, 0.05f}, room, buffer);
    ASSERT_TRUE(c8);
    EXPECT_EQ(*c8, 28 + 3 * room.size());
    ASSERT_TRUE(DecodeRoomCloud(std::span(buffer.data(), *c8), points));
    ASSERT_EQ(points.size(), room.size());
    for (std::size_t i = 0; i < room.size(); ++i)
      EXPECT_LE((points[i] - room[i]).cwiseAbs().maxCoeff(), 0.0251f);
    const std::vector<Eigen::Vector3f> wide{Eigen::Vector3f(6.5f, 0, 0)};
    EXPECT_EQ(
        EncodeRoomCloud({2, 7, 4, CloudEncoding::kQuantised8, 0.05f}, wide, buffer).error().code,
        Errc::kInvalidArgument);
  }
  // Bad input: CRC, capacity, length, a point beyond the quantised range.
  auto c = *EncodeRoomCloud({2, 7, 4, CloudEncoding::kQuantised16, 0.01f}, cloud, buffer);
  std::vector<std::uint8_t> m(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(c));
  m[30] ^= 1;
  EXPECT_EQ(DecodeRoomCloud(m, points).error().code, Errc::kChecksum);
  BoundedVector<Eigen::Vector3f> few(10);
  EXPECT_EQ(DecodeRoomCloud(std::span(buffer.data(), c), few).error().code,
            Errc::kCapacityExceeded);
  m.assign(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(c));
  m.insert(m.end() - 4, {0, 0});
  Reseal(m);
  EXPECT_EQ(DecodeRoomCloud(m, points).error().code, Errc::kMalformed);
  const std::vector<Eigen::Vector3f> far{Eigen::Vector3f(400, 0, 0)};
  EXPECT_EQ(
      EncodeRoomCloud({2, 7, 4, CloudEncoding::kQuantised16, 0.01f}, far, buffer).error().code,
      Errc::kInvalidArgument);
  std::vector<std::uint8_t> d(
      buffer.begin(),
      buffer.begin() + static_cast<std::ptrdiff_t>(*EncodeRoomDescriptor({2, 7, 4}, sc, buffer)));
  d[15] = 90;  // rings beyond the maximum
  Reseal(d);
  EXPECT_EQ(DecodeRoomDescriptor(d, back).error().code, Errc::kMalformed);
}

TEST(RoomMatcher, ConsistencyCheckRejectsAPlantedSymmetricMismatch) {
  // Three true matches agree on the map-to-map transform; two identical rooms elsewhere in a
  // symmetric building align just as well, but to transforms shifted by the building's period.
  const Eigen::Isometry3d truth = Planar(4.0, -2.0, 0.7);
  std::vector<RoomMatch> matches;
  for (int i = 0; i < 3; ++i) {
    RoomMatch m;
    m.room_a = static_cast<std::uint32_t>(i);
    m.T_a_b = truth * Planar(0.02 * i, -0.01 * i, 0.002 * i);
    matches.push_back(m);
  }
  for (int i = 0; i < 2; ++i) {
    RoomMatch m;
    m.room_a = 10u + static_cast<std::uint32_t>(i);
    m.T_a_b = Planar(6.0 * (i + 1), 0, 0) * truth;  // the room next door, and the one after
    matches.insert(matches.begin() + 1, m);
  }
  RoomMatchConfig config;
  std::uint32_t keep[8];
  const std::size_t n = ConsistentMatches(matches, config, keep);
  ASSERT_EQ(n, 3u);
  for (std::size_t i = 0; i < n; ++i) EXPECT_LT(matches[keep[i]].room_a, 10u);
  // One match alone cannot be checked: nothing is kept.
  EXPECT_EQ(ConsistentMatches(std::span(matches).first(1), config, keep), 0u);
  // Two symmetric mismatches alone disagree with each other: nothing is kept.
  EXPECT_EQ(ConsistentMatches(std::span(matches).subspan(1, 2), config, keep), 0u);
}

TEST(RoomMatcher, ConsistencyCheckWaitsOnATieBetweenTwoHypotheses) {
  // Two rooms of a symmetric pair each matched twice, one pair agreeing with the truth and the
  // other with the building shifted by its period: 2 against 2 is no answer yet.
  const Eigen::Isometry3d truth = Planar(4.0, -2.0, 0.7), shifted = Planar(6.0, 0, 0) * truth;
  std::vector<RoomMatch> matches;
  for (int i = 0; i < 4; ++i) {
    RoomMatch m;
    m.room_a = static_cast<std::uint32_t>(i);
    m.T_a_b = (i % 2 == 0 ? shifted : truth) * Planar(0.01 * i, 0, 0);
    matches.push_back(m);
  }
  RoomMatchConfig config;
  std::uint32_t keep[8];
  EXPECT_EQ(ConsistentMatches(matches, config, keep), 0u);
  // A third match for the truth breaks the tie.
  RoomMatch third;
  third.room_a = 9;
  third.T_a_b = truth;
  matches.push_back(third);
  ASSERT_EQ(ConsistentMatches(matches, config, keep), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(matches[keep[i]].room_a % 2, 1u);  // 1, 3 and 9
}

TEST(RoomMatcher, FineAlignmentRecoversTheMapToMapTransform) {
  // The same room (furnished, so not symmetric) seen by two robots whose maps differ by truth.
  auto room = test::BoxRoom(6, 4, 2.4, 6000, 0.01, 5,
                            Eigen::Isometry3d(Eigen::Translation3d(-3, -2, 0)), false);
  const auto box = test::BoxRoom(1.0, 0.6, 0.8, 1500, 0.01, 6,
                                 Eigen::Isometry3d(Eigen::Translation3d(1.2, 0.6, 0)), false);
  room.insert(room.end(), box.begin(), box.end());
  const Eigen::Isometry3d truth = Planar(5.0, 1.0, 2.0);  // map a from map b
  const Eigen::Isometry3d T_ma_ra = Planar(2.0, 3.0, 0.1);
  // Robot b's room frame is the room rotated by a quarter turn (frames are defined up to them)
  // and off by a few centimetres, as its own estimate would be.
  const Eigen::Isometry3d T_ra_rb = Planar(0.04, -0.03, std::numbers::pi / 2 + 0.01);
  const Eigen::Isometry3d T_mb_rb = truth.inverse() * T_ma_ra * T_ra_rb;
  std::vector<Eigen::Vector3f> cloud_b;
  for (const auto& p : room)
    cloud_b.push_back((T_ra_rb.inverse() * p.cast<double>()).cast<float>());
  RoomMatcher matcher;
  ASSERT_TRUE(matcher.Init({}));
  RoomMatch m;
  ASSERT_TRUE(matcher.FineAlign(room, T_ma_ra, cloud_b, T_mb_rb, std::numbers::pi / 2, m));
  const Eigen::Isometry3d e = truth.inverse() * m.T_a_b;
  EXPECT_LT(e.translation().norm(), 0.02);
  EXPECT_LT(Eigen::AngleAxisd(e.linear()).angle(), 0.005);
  EXPECT_LT(m.fitness_m2, 0.01);
  // A wrong seed a quarter turn off is found by trying the others.
  RoomMatch m2;
  ASSERT_TRUE(matcher.FineAlign(room, T_ma_ra, cloud_b, T_mb_rb, 0.0, m2));
  EXPECT_LT((truth.inverse() * m2.T_a_b).translation().norm(), 0.02);
}

TEST(CollaborativeGraph, RecoversAnotherRobotsSE3OriginFromRoomsAndWalls) {
  // Robot 2's map in robot 1's: a planar offset and a different height (robot 2 started on a
  // step: its floor is 0.7 m below its map origin, robot 1's 0.5 m).
  Eigen::Isometry3d truth = Planar(7.0, -3.0, 1.1);
  truth.translation().z() = 0.2;
  const double floor_a = -0.5, floor_b = -0.7;
  DistilledGraph a, b;
  a.Init(16, 4);
  b.Init(16, 4);
  AddRoom(a, 0, 0, Planar(2, 3, 0.3), 1);
  AddRoom(a, 4, 1, Planar(10, 2, 0.3), 1);
  AddRoom(b, 10, 5, truth.inverse() * Planar(2, 3, 0.3), 1);
  AddRoom(b, 14, 6, truth.inverse() * Planar(10, 2, 0.3), 1);
  // What a room match suggests: off by 30 cm, 3 degrees of yaw and a degree of roll.
  const Eigen::Isometry3d initial =
      truth * Planar(0.3, -0.2, 0.05) * Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitX());
  for (bool walls : {false, true}) {
    CollaborativeGraph g;
    ASSERT_TRUE(g.Init({}, 1));
    ASSERT_TRUE(g.SetInitial(2, initial));
    std::uint32_t wall_nodes[2][8];
    for (std::size_t r = 0; r < 2; ++r) {
      auto ra = g.AddRoom(1, a.rooms[r], floor_a);
      auto rb = g.AddRoom(2, b.rooms[r], floor_b);
      ASSERT_TRUE(ra && rb);
      ASSERT_TRUE(g.AddRoomRoom(*ra, *rb));
      if (!walls) continue;
      for (std::size_t w = 0; w < 4; ++w) {
        auto wa = g.AddWall(1, a.walls[r * 4 + w]);
        auto wb = g.AddWall(2, b.walls[r * 4 + w]);
        ASSERT_TRUE(wa && wb);
        wall_nodes[0][r * 4 + w] = *wa;
        wall_nodes[1][r * 4 + w] = *wb;
        ASSERT_TRUE(g.AddWallWall(*wa, *wb));
      }
    }
    ASSERT_TRUE(g.Solve());
    const Eigen::Isometry3d e = truth.inverse() * g.T_self_robot(2);
    EXPECT_LT(e.translation().norm(), 1e-3) << (walls ? "rooms and walls" : "rooms");
    EXPECT_LT(Eigen::AngleAxisd(e.linear()).angle(), 1e-4) << (walls ? "rooms and walls" : "rooms");
    EXPECT_EQ(g.rooms(), 4u);
    EXPECT_LT((g.room_centre(1) - Eigen::Vector3d(2, 3, floor_a)).norm(), 1e-3);
    if (!walls) continue;
    // Robot 2's walls, refined and expressed in robot 1's frame, are robot 1's walls.
    EXPECT_EQ(g.walls(), 16u);
    for (std::size_t w = 0; w < 8; ++w) {
      const DistilledWall mine = g.wall(wall_nodes[0][w]), theirs = g.wall(wall_nodes[1][w]);
      EXPECT_EQ(g.wall_robot(wall_nodes[1][w]), 2);
      EXPECT_GT(theirs.normal.dot(a.walls[w].normal), std::cos(1e-4));
      EXPECT_NEAR(theirs.d, a.walls[w].d, 1e-3);
      EXPECT_NEAR(mine.d, a.walls[w].d, 1e-3);
      EXPECT_EQ(theirs.id, b.walls[w].id);
    }
  }
  CollaborativeGraph g;
  ASSERT_TRUE(g.Init({}, 1));
  EXPECT_FALSE(g.AddRoom(3, a.rooms[0], floor_a));  // no initial origin for robot 3
  EXPECT_FALSE(g.SetInitial(99, truth));            // beyond max_robots
  EXPECT_FALSE(g.SetInitial(1, truth));             // self is the gauge
  EXPECT_FALSE(g.AddRoomRoom(0, 1));                // no such nodes
  DistilledWall bad = a.walls[0];
  bad.d = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(g.AddWall(1, bad));
  EXPECT_FALSE(g.Init({}, 0));  // robot ids start at 1
}

// A corridor's centre along its length is the centroid of the stretch its robot saw: two
// robots that saw different stretches place it 4 m apart along it (benchmark m011: a tie in
// all directions slid a merged origin 7.6 m). One shared room places robot 2; the corridor
// pair, tied across its axis only, must not pull it along, and a shift across the corridor
// is still held.
TEST(CollaborativeGraph, ACorridorIsTiedAcrossItsAxisOnly) {
  const Eigen::Isometry3d truth = Planar(7.0, -3.0, 1.1);
  DistilledGraph a, b;
  a.Init(16, 4);
  b.Init(16, 4);
  AddRoom(a, 0, 0, Planar(2, 3, 0.3), 1);
  AddRoom(b, 10, 5, truth.inverse() * Planar(2, 3, 0.3), 1);
  const double yaw_a = 0.3;  // the corridor's x axis (across it) in robot 1's frame
  const Eigen::Vector2d across(std::cos(yaw_a), std::sin(yaw_a)), along(-std::sin(yaw_a), std::cos(yaw_a));
  auto corridor = [&](std::uint32_t id, const Eigen::Vector2d& centre_in_a) {
    DistilledRoom r;
    r.id = id;
    r.version = 1;
    r.shape = RoomShape::kCorridor;
    r.size_x_m = 2.0;
    r.centre = (truth.inverse() * Eigen::Vector3d(centre_in_a.x(), centre_in_a.y(), 0)).head<2>();
    r.yaw_rad = yaw_a - 1.1;
    return r;
  };
  DistilledRoom corridor_a = corridor(1, Eigen::Vector2d(10, 2));
  corridor_a.centre = Eigen::Vector2d(10, 2);
  corridor_a.yaw_rad = yaw_a;
  const Eigen::Isometry3d initial = truth * Planar(0.3, -0.2, 0.05);
  for (const double along_m : {4.0, -6.0}) {
    CollaborativeGraph g;
    ASSERT_TRUE(g.Init({}, 1));
    ASSERT_TRUE(g.SetInitial(2, initial));
    auto ra = g.AddRoom(1, a.rooms[0], 0.0);
    auto rb = g.AddRoom(2, b.rooms[0], 0.0);
    ASSERT_TRUE(ra && rb);
    ASSERT_TRUE(g.AddRoomRoom(*ra, *rb));
    auto ca = g.AddRoom(1, corridor_a, 0.0);
    auto cb = g.AddRoom(2, corridor(6, Eigen::Vector2d(10, 2) + along_m * along), 0.0);
    ASSERT_TRUE(ca && cb);
    ASSERT_TRUE(g.AddRoomRoom(*ca, *cb));
    ASSERT_TRUE(g.Solve());
    const Eigen::Isometry3d e = truth.inverse() * g.T_self_robot(2);
    EXPECT_LT(e.translation().norm(), 1e-3) << along_m << " m along";
    EXPECT_LT(Eigen::AngleAxisd(e.linear()).angle(), 1e-4) << along_m << " m along";
    // Each corridor node stays where its own robot put it along the corridor.
    EXPECT_NEAR(along.dot((g.room_centre(*cb) - g.room_centre(*ca)).head<2>()), along_m, 1e-2);
  }
  // 0.5 m across the corridor is a contradiction the solve must settle, not ignore: the two
  // corridor nodes meet across it (the tie is 1 cm, each robot's room and corridor 7 cm).
  CollaborativeGraph g;
  ASSERT_TRUE(g.Init({}, 1));
  ASSERT_TRUE(g.SetInitial(2, initial));
  auto ra = g.AddRoom(1, a.rooms[0], 0.0);
  auto rb = g.AddRoom(2, b.rooms[0], 0.0);
  auto ca = g.AddRoom(1, corridor_a, 0.0);
  auto cb = g.AddRoom(2, corridor(6, Eigen::Vector2d(10, 2) + 0.5 * across + 3.0 * along), 0.0);
  ASSERT_TRUE(ra && rb && ca && cb);
  ASSERT_TRUE(g.AddRoomRoom(*ra, *rb));
  ASSERT_TRUE(g.AddRoomRoom(*ca, *cb));
  ASSERT_TRUE(g.Solve());
  EXPECT_LT(std::fabs(across.dot((g.room_centre(*cb) - g.room_centre(*ca)).head<2>())), 0.05);
  EXPECT_GT((g.T_self_robot(2).translation() - truth.translation()).norm(), 0.05) << "robot 2 moved";
}

// The feedback gate (feedback_gate.hpp): a prior that matches the own wall within the summed
// covariances passes the chi-square 99 % bound for 3 degrees of freedom; one shifted or turned
// by several sigmas, or facing the other way, does not.
TEST(FeedbackGate, APriorPassesWithinItsCovariancesOnly) {
  DistilledWall own;
  own.normal = Eigen::Vector3d(1, 0, 0);
  own.d = -2.0;
  own.covariance = Eigen::Vector3d(1e-6, 1e-6, 1e-4).asDiagonal();  // 1 mrad, 1 cm
  PlanePrior prior;
  prior.normal = own.normal;
  prior.d = own.d;
  prior.covariance = Eigen::Vector3d(25e-6, 25e-6, 1e-4).asDiagonal();  // 5 mrad, 1 cm
  const double bound = CollabSessionConfig{}.feedback_gate_chi2;
  EXPECT_NEAR(PriorDisagreement(prior, own), 0.0, 1e-12);
  // 2 cm along the normal against a summed sigma of 1.41 cm: 2.0 squared sigmas.
  prior.d = own.d + 0.02;
  EXPECT_NEAR(PriorDisagreement(prior, own), 2.0, 1e-9);
  EXPECT_LE(PriorDisagreement(prior, own), bound);
  // 10 cm: 50, a wall the origin put elsewhere.
  prior.d = own.d + 0.10;
  EXPECT_GT(PriorDisagreement(prior, own), bound);
  // Turned by 1.6 degrees about the vertical (the wrong view's yaw) against 5.1 mrad: gated.
  prior.d = own.d;
  prior.normal = Eigen::AngleAxisd(1.6 * M_PI / 180, Eigen::Vector3d::UnitZ()) * own.normal;
  EXPECT_GT(PriorDisagreement(prior, own), bound);
  // Turned by 0.2 degrees: within.
  prior.normal = Eigen::AngleAxisd(0.2 * M_PI / 180, Eigen::Vector3d::UnitZ()) * own.normal;
  EXPECT_LE(PriorDisagreement(prior, own), bound);
  // Facing the other way, or a covariance that is not positive definite: never agrees.
  prior.normal = -own.normal;
  EXPECT_TRUE(std::isinf(PriorDisagreement(prior, own)));
  prior.normal = own.normal;
  prior.covariance = -Eigen::Matrix3d::Identity();
  own.covariance.setZero();
  EXPECT_TRUE(std::isinf(PriorDisagreement(prior, own)));
}

}  // namespace

namespace {

struct RecordingOutbox final : CollabOutbox {
  struct Sent {
    CollabMessageType type;
    std::uint16_t to;
    std::vector<std::uint8_t> bytes;
  };
  std::vector<Sent> sent;
  void Send(CollabMessageType type,
            std::uint16_t to,
            std::span<const std::uint8_t> bytes) override {
    sent.push_back({type, to, {bytes.begin(), bytes.end()}});
  }
};

// Robot 1's session, room for two peers.
CollabSessionConfig RobotOneOfTwoPeers() {
  CollabSessionConfig config;
  config.robot = 1;
  config.max_peers = 2;
  return config;
}

// A peer's distilled graph holding one four-wall room.
DistilledGraph OneRoomGraphOf(std::uint16_t robot) {
  DistilledGraph g;
  g.Init(16, 4);
  g.robot = robot;
  AddRoom(g, 0, 0, Planar(2, 3, 0.3), 1);
  return g;
}

std::vector<std::uint8_t> EncodedGraph(const DistilledGraph& g, std::uint32_t since) {
  std::vector<std::uint8_t> bytes(64 * 1024);
  auto n = EncodeDistilled(g, since, bytes);
  EXPECT_TRUE(n);
  bytes.resize(n ? *n : 0);
  return bytes;
}

}  // namespace

// collab_session.hpp: after Init only Ceres allocates, and Receive has no Ceres: a peer's
// messages (its first graph, which creates the peer, a delta, its descriptor's refusal, a
// corrupted message, one claiming to be ours, a request for a room we do not have) are decoded
// into the stores sized at Init. The outbox is the caller's (the node's is Fast DDS, which
// allocates); this one discards.
TEST(CollabSession, ReceivingAPeersMessagesAllocatesNothing) {
  struct DiscardingOutbox final : CollabOutbox {
    void Send(CollabMessageType, std::uint16_t, std::span<const std::uint8_t>) override {}
  };
  CollabSession session;
  ASSERT_TRUE(session.Init(RobotOneOfTwoPeers(), SGraphConfig{}, -0.5));
  DistilledGraph g = OneRoomGraphOf(2);
  g.version = 1;
  const auto full = EncodedGraph(g, 0);
  g.version = 5;
  g.walls[0].version = 5;
  g.walls[0].d += 0.1;
  const auto delta = EncodedGraph(g, 1);
  auto corrupt = full;
  corrupt[30] ^= 0x10;
  g.robot = 1;
  const auto from_us = EncodedGraph(g, 0);
  ScanContext sc;
  const std::vector<Eigen::Vector3f> points = {{1, 0, 1}, {0, 2, 0.5f}, {-1, -1, 2}};
  ASSERT_TRUE(sc.Build(points, {10, 30, 12.0f, 0.0f}));
  std::vector<std::uint8_t> descriptor(RoomDescriptorEncodedSize(sc));
  ASSERT_TRUE(EncodeRoomDescriptor({2, 0, 1}, sc, descriptor));
  std::vector<std::uint8_t> request(kRoomCloudRequestBytes);
  ASSERT_TRUE(EncodeRoomCloudRequest({2, 1, 42, 1}, request));
  DiscardingOutbox out;
  std::uint64_t allocations = 0;
  bool held = false, applied = false, refused = true;
  {
    test::AllocationScope scope;
    held = session.Receive(CollabMessageType::kDistilledGraph, full, out).has_value();
    applied = session.Receive(CollabMessageType::kDistilledGraph, delta, out).has_value();
    refused = refused && !session.Receive(CollabMessageType::kDistilledGraph, corrupt, out).has_value();
    refused = refused && !session.Receive(CollabMessageType::kDistilledGraph, from_us, out).has_value();
    refused = refused && !session.Receive(CollabMessageType::kRoomDescriptor, descriptor, out).has_value();
    refused = refused && !session.Receive(CollabMessageType::kRoomCloudRequest, request, out).has_value();
    allocations = scope.allocations();
  }
  EXPECT_EQ(allocations, 0u);
  EXPECT_TRUE(held && applied && refused);
  ASSERT_NE(session.peer_graph(2), nullptr);
  EXPECT_NEAR(session.peer_graph(2)->walls[0].d, g.walls[0].d, 1e-6);
  EXPECT_EQ(session.stats().malformed, 2u);
  EXPECT_EQ(session.stats().descriptors_mismatched, 1u);
  EXPECT_EQ(session.stats().requests_unknown, 1u);
}

TEST(CollabSession, CountsAndRefusesBadOrHostileMessagesAndKeepsWorking) {
  CollabSession session;
  ASSERT_TRUE(session.Init(RobotOneOfTwoPeers(), SGraphConfig{}, -0.5));
  RecordingOutbox out;

  // A peer's distilled graph arrives and is held.
  DistilledGraph g = OneRoomGraphOf(2);
  g.version = 1;
  g.has_floor = true;
  g.floor_z_m = -0.6;
  auto bytes = EncodedGraph(g, 0);
  ASSERT_TRUE(session.Receive(CollabMessageType::kDistilledGraph, bytes, out));
  ASSERT_NE(session.peer_graph(2), nullptr);
  EXPECT_EQ(session.peer_graph(2)->walls.size(), 4u);
  EXPECT_DOUBLE_EQ(session.peer_graph(2)->floor_z_m, static_cast<double>(-0.6f));
  EXPECT_EQ(session.peer_stats(0).bytes_received[0], bytes.size());

  // A flipped bit fails the CRC: counted, nothing changes. Not against the peer: a corrupt
  // message's sender id cannot be trusted (garbage must not create or blame a peer).
  auto corrupt = bytes;
  corrupt[30] ^= 0x10;
  EXPECT_FALSE(session.Receive(CollabMessageType::kDistilledGraph, corrupt, out));
  EXPECT_EQ(session.stats().malformed, 1u);
  EXPECT_EQ(session.peer_stats(0).malformed, 0u);
  EXPECT_EQ(session.peers(), 1u);
  // A message claiming to come from ourselves, and one whose type lies about its content.
  g.robot = 1;
  EXPECT_FALSE(session.Receive(CollabMessageType::kDistilledGraph, EncodedGraph(g, 0), out));
  EXPECT_FALSE(session.Receive(CollabMessageType::kRoomCloud, bytes, out));
  EXPECT_EQ(session.stats().malformed, 3u);

  // A delta whose base was never received is applied and counted as a gap.
  g.robot = 2;
  g.version = 5;
  g.walls[0].version = 5;
  g.walls[0].d += 0.1;
  EXPECT_TRUE(session.Receive(CollabMessageType::kDistilledGraph, EncodedGraph(g, 3), out));
  EXPECT_EQ(session.peer_stats(0).graph_gaps, 1u);
  EXPECT_NEAR(session.peer_graph(2)->walls[0].d, g.walls[0].d, 1e-6);

  // Peers beyond max_peers are refused with a counter.
  for (int robot : {3, 4}) {
    g.robot = static_cast<std::uint16_t>(robot);
    static_cast<void>(session.Receive(CollabMessageType::kDistilledGraph, EncodedGraph(g, 0), out));
  }
  EXPECT_EQ(session.peers(), 2u);
  EXPECT_EQ(session.stats().peers_refused, 1u);

  // A descriptor of another shape than ours cannot be compared: refused with a reason.
  ScanContext sc;
  const std::vector<Eigen::Vector3f> points = {{1, 0, 1}, {0, 2, 0.5f}, {-1, -1, 2}};
  ASSERT_TRUE(sc.Build(points, {10, 30, 12.0f, 0.0f}));
  std::vector<std::uint8_t> descriptor(RoomDescriptorEncodedSize(sc));
  ASSERT_TRUE(EncodeRoomDescriptor({2, 0, 1}, sc, descriptor));
  EXPECT_FALSE(session.Receive(CollabMessageType::kRoomDescriptor, descriptor, out));
  EXPECT_EQ(session.stats().descriptors_mismatched, 1u);

  // Requests: for a room we do not have (counted), for another robot (ignored, not an error).
  std::vector<std::uint8_t> request(kRoomCloudRequestBytes);
  ASSERT_TRUE(EncodeRoomCloudRequest({2, 1, 42, 1}, request));
  EXPECT_FALSE(session.Receive(CollabMessageType::kRoomCloudRequest, request, out));
  EXPECT_EQ(session.stats().requests_unknown, 1u);
  ASSERT_TRUE(EncodeRoomCloudRequest({2, 3, 42, 1}, request));
  EXPECT_TRUE(session.Receive(CollabMessageType::kRoomCloudRequest, request, out));
  EXPECT_TRUE(out.sent.empty());

  // A room cloud nobody asked for is not cached.
  std::vector<std::uint8_t> cloud(RoomCloudEncodedSize(CloudEncoding::kQuantised16, 3));
  ASSERT_TRUE(EncodeRoomCloud({2, 0, 1, CloudEncoding::kQuantised16, 0.01f}, points, cloud));
  EXPECT_FALSE(session.Receive(CollabMessageType::kRoomCloud, cloud, out));
  EXPECT_EQ(session.stats().clouds_unsolicited, 1u);

  // Still working: nothing to match yet, and a valid update is taken.
  EXPECT_FALSE(session.Match(out));
  g.robot = 2;
  g.version = 6;
  g.walls[1].version = 6;
  EXPECT_TRUE(session.Receive(CollabMessageType::kDistilledGraph, EncodedGraph(g, 5), out));
  EXPECT_EQ(session.peer_graph(2)->version, 6u);
  EXPECT_FALSE(session.merged(2));
  EXPECT_GT(session.stats().store_bytes, 0u);
}

TEST(RoomMessages, CloudRequestRoundTripAndRejections) {
  std::vector<std::uint8_t> bytes(kRoomCloudRequestBytes);
  ASSERT_TRUE(EncodeRoomCloudRequest({2, 5, 17, 9}, bytes));
  auto q = DecodeRoomCloudRequest(bytes);
  ASSERT_TRUE(q);
  EXPECT_EQ(q->from, 2);
  EXPECT_EQ(q->to, 5);
  EXPECT_EQ(q->room, 17u);
  EXPECT_EQ(q->version, 9u);
  auto bad = bytes;
  bad[10] ^= 1;
  EXPECT_EQ(DecodeRoomCloudRequest(bad).error().code, Errc::kChecksum);
  EXPECT_FALSE(DecodeRoomCloudRequest(std::span(bytes).first(10)));
  ASSERT_TRUE(EncodeRoomCloudRequest({2, 2, 17, 9}, bytes));  // to itself
  EXPECT_FALSE(DecodeRoomCloudRequest(bytes));
}
}  // namespace msgraphs::core
