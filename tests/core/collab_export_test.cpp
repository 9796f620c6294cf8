// SPDX-License-Identifier: MIT
// CollabSession::ExportReceived (the runtime checkpoint's snapshot of the session): a session
// rebuilt from the messages a first one exported holds the same peers, graphs, descriptors and
// free space (it exports the same bytes again), goes on alike when the peers' next deltas
// arrive, and exporting allocates nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/collab/distilled_codec.hpp"
#include "msgraphs/core/collab/free_space_codec.hpp"
#include "msgraphs/core/collab/room_messages.hpp"
#include "msgraphs/core/descriptors/scan_context.hpp"
#include "msgraphs/core/perception/free_space_grid.hpp"

namespace msgraphs::core {
namespace {

struct Message {
  CollabMessageType type;
  std::vector<std::uint8_t> bytes;
  bool operator==(const Message&) const = default;
};

struct RecordingOutbox final : CollabOutbox {
  std::vector<Message> sent;
  void Send(CollabMessageType type, std::uint16_t, std::span<const std::uint8_t> bytes) override {
    sent.push_back({type, {bytes.begin(), bytes.end()}});
  }
};

struct DiscardingOutbox final : CollabOutbox {
  void Send(CollabMessageType, std::uint16_t, std::span<const std::uint8_t>) override {}
};

CollabSessionConfig RobotOne() {
  CollabSessionConfig config;
  config.robot = 1;
  config.max_peers = 3;
  return config;
}

// Robot `robot`'s graph: `rooms` rooms of four walls in a row along x, at `version`.
DistilledGraph GraphOf(std::uint16_t robot, int rooms, std::uint32_t version) {
  DistilledGraph g;
  g.Init(64, 16);
  g.robot = robot;
  g.version = version;
  for (int r = 0; r < rooms; ++r) {
    DistilledRoom room;
    room.id = static_cast<std::uint32_t>(r);
    room.version = version;
    room.centre = {7.0 * r + robot, 1.0};
    room.size_x_m = 6;
    room.size_y_m = 4;
    const Eigen::Vector2d c = room.centre;
    const Eigen::Vector3d normals[4] = {Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitX(),
                                        Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitY()};
    const double half[4] = {3, 3, 2, 2};
    for (int i = 0; i < 4; ++i) {
      DistilledWall w;
      w.id = static_cast<std::uint32_t>(4 * r + i);
      w.version = version;
      w.normal = normals[i];
      const Eigen::Vector3d on = Eigen::Vector3d(c.x(), c.y(), 0) - normals[i] * half[i];
      w.d = -w.normal.dot(on);
      w.covariance = Eigen::Vector3d(1e-4, 2e-4, 4e-4).asDiagonal();
      w.a = on.head<2>();
      w.b = w.a + Eigen::Vector2d(-normals[i].y(), normals[i].x());
      g.walls.push_back(w);
      room.walls[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(w.id);
    }
    g.rooms.push_back(room);
  }
  g.has_floor = true;
  g.floor_centre = {3.5, 1.0};
  return g;
}

std::vector<std::uint8_t> Encoded(const DistilledGraph& g, std::uint32_t since) {
  std::vector<std::uint8_t> bytes(DistilledEncodedSize(g, since));
  auto n = EncodeDistilled(g, since, bytes);
  EXPECT_TRUE(n);
  bytes.resize(n ? *n : 0);
  return bytes;
}

std::vector<std::uint8_t> Descriptor(const CollabSessionConfig& config, std::uint16_t robot,
                                     std::uint32_t room, std::uint32_t version) {
  const ScanContextConfig& sc_config = config.descriptor.scan_context;
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 400; ++i) {
    const float a = 0.0157f * static_cast<float>(i);
    points.emplace_back((2.0f + static_cast<float>(room)) * std::cos(a), 1.5f * std::sin(a),
                        0.2f + 0.005f * static_cast<float>(i % 200));
  }
  ScanContext sc;
  EXPECT_TRUE(sc.Build(points, sc_config));
  std::vector<std::uint8_t> bytes(RoomDescriptorEncodedSize(sc));
  EXPECT_TRUE(EncodeRoomDescriptor({robot, room, version}, sc, bytes));
  return bytes;
}

// A free-space summary of robot `robot`: the cells a sensor at the origin saw through to a
// ring of returns.
std::vector<std::uint8_t> FreeSpace(const CollabSessionConfig& config, std::uint16_t robot,
                                    std::uint32_t version) {
  FreeSpaceGridConfig grid_config;
  grid_config.width = 120;
  grid_config.height = 120;
  grid_config.origin_m = {-6.0f, -6.0f};
  FreeSpaceGrid grid;
  EXPECT_TRUE(grid.Init(grid_config));
  std::vector<Eigen::Vector3f> ring;
  for (int i = 0; i < 720; ++i) {
    const float a = 0.00873f * static_cast<float>(i);
    ring.emplace_back(4.0f * std::cos(a), 3.0f * std::sin(a), 0.5f);
  }
  grid.Integrate({0, 0, 0.8f}, ring, 0.0f);
  FreeSpaceSummary summary;
  EXPECT_TRUE(summary.Init(config.free_space));
  EXPECT_TRUE(summary.Build(grid, {}));
  std::vector<std::uint8_t> bytes(64 * 1024);
  auto n = EncodeFreeSpace({robot, version}, summary, bytes);
  EXPECT_TRUE(n);
  bytes.resize(n ? *n : 0);
  return bytes;
}

// Robot 1 has heard from robots 2 (graph in a full message and a delta, two descriptors, free
// space twice) and 3 (a graph only).
void HearFromPeers(CollabSession& session, const CollabSessionConfig& config) {
  DiscardingOutbox out;
  DistilledGraph two = GraphOf(2, 2, 3);
  ASSERT_TRUE(session.Receive(CollabMessageType::kDistilledGraph, Encoded(two, 0), out));
  ASSERT_TRUE(session.Receive(CollabMessageType::kRoomDescriptor, Descriptor(config, 2, 0, 3), out));
  ASSERT_TRUE(session.Receive(CollabMessageType::kFreeSpace, FreeSpace(config, 2, 1), out));
  ASSERT_TRUE(session.Receive(CollabMessageType::kDistilledGraph, Encoded(GraphOf(3, 1, 2), 0), out));
  two.version = 5;
  two.walls[1].version = 5;
  two.walls[1].d += 0.05;
  ASSERT_TRUE(session.Receive(CollabMessageType::kDistilledGraph, Encoded(two, 3), out));
  ASSERT_TRUE(session.Receive(CollabMessageType::kRoomDescriptor, Descriptor(config, 2, 1, 5), out));
  ASSERT_TRUE(session.Receive(CollabMessageType::kFreeSpace, FreeSpace(config, 2, 4), out));
}

void ExpectSameGraph(const DistilledGraph& a, const DistilledGraph& b) {
  EXPECT_EQ(a.robot, b.robot);
  EXPECT_EQ(a.version, b.version);
  ASSERT_EQ(a.walls.size(), b.walls.size());
  for (std::size_t i = 0; i < a.walls.size(); ++i) {
    EXPECT_EQ(a.walls[i].id, b.walls[i].id);
    EXPECT_EQ(a.walls[i].version, b.walls[i].version);
    EXPECT_EQ(a.walls[i].d, b.walls[i].d);
  }
  ASSERT_EQ(a.rooms.size(), b.rooms.size());
  for (std::size_t i = 0; i < a.rooms.size(); ++i) EXPECT_EQ(a.rooms[i].id, b.rooms[i].id);
  EXPECT_EQ(a.has_floor, b.has_floor);
}

TEST(CollabExport, ASessionRebuiltFromItsExportHoldsWhatItsPeersSent) {
  const CollabSessionConfig config = RobotOne();
  CollabSession live;
  ASSERT_TRUE(live.Init(config, SGraphConfig{}, -0.5));
  ASSERT_NO_FATAL_FAILURE(HearFromPeers(live, config));

  RecordingOutbox exported;
  const CollabExportStats stats = live.ExportReceived(exported);
  EXPECT_EQ(stats.failed, 0u);
  // Robot 2: its graph, two descriptors, its newest free space; robot 3: its graph.
  ASSERT_EQ(exported.sent.size(), 5u);
  EXPECT_EQ(stats.messages, 5u);
  std::size_t bytes = 0;
  for (const Message& m : exported.sent) bytes += m.bytes.size();
  EXPECT_EQ(stats.bytes, bytes);

  CollabSession restored;
  ASSERT_TRUE(restored.Init(config, SGraphConfig{}, -0.5));
  DiscardingOutbox out;
  for (const Message& m : exported.sent) EXPECT_TRUE(restored.Receive(m.type, m.bytes, out));
  EXPECT_EQ(restored.peers(), live.peers());
  for (std::uint16_t robot : {std::uint16_t{2}, std::uint16_t{3}}) {
    ASSERT_NE(restored.peer_graph(robot), nullptr);
    ExpectSameGraph(*live.peer_graph(robot), *restored.peer_graph(robot));
  }
  // Everything it holds exports as the same bytes again (descriptors, the free space's
  // version and cells included).
  RecordingOutbox again;
  restored.ExportReceived(again);
  EXPECT_EQ(again.sent, exported.sent);

  // The peers go on: their next deltas apply to both alike.
  DistilledGraph two = GraphOf(2, 3, 7);
  for (CollabSession* s : {&live, &restored})
    ASSERT_TRUE(s->Receive(CollabMessageType::kDistilledGraph, Encoded(two, 5), out));
  ExpectSameGraph(*live.peer_graph(2), *restored.peer_graph(2));
  EXPECT_EQ(restored.peer_stats(0).graph_gaps, 0u);
  // And an older free space, late, is ignored by both (the restored one knows its version).
  for (CollabSession* s : {&live, &restored})
    ASSERT_TRUE(s->Receive(CollabMessageType::kFreeSpace, FreeSpace(config, 2, 2), out));
  RecordingOutbox live_after, restored_after;
  live.ExportReceived(live_after);
  restored.ExportReceived(restored_after);
  EXPECT_EQ(live_after.sent, restored_after.sent);
}

TEST(CollabExport, ExportingAllocatesNothingAndAnEmptySessionExportsNothing) {
  const CollabSessionConfig config = RobotOne();
  CollabSession session;
  ASSERT_TRUE(session.Init(config, SGraphConfig{}, -0.5));
  DiscardingOutbox out;
  EXPECT_EQ(session.ExportReceived(out).messages, 0u);
  ASSERT_NO_FATAL_FAILURE(HearFromPeers(session, config));
  test::AllocationScope scope;
  const CollabExportStats stats = session.ExportReceived(out);
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_EQ(stats.messages, 5u);
}

}  // namespace
}  // namespace msgraphs::core
