// SPDX-License-Identifier: MIT
// Place clouds (place_cloud.hpp) from a mapped room: cropped to the disc and the obstacle band,
// built without allocating; and the session's side of the fallback: a peer's place request is
// answered at the next Publish, once per place, within the peer's byte budget, and a cloud
// nobody asked for is refused.
#include <gtest/gtest.h>

#include <vector>

#include "alloc_counter.hpp"
#include "mapped_room.hpp"
#include "msgraphs/core/collab/collab_publisher.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/collab/place_cloud.hpp"
#include "msgraphs/core/collab/place_messages.hpp"

namespace msgraphs::core {
namespace {

using test::MapTheRoom;

// The room's map frame starts at (2, 4) (mapped_room.hpp): its centre (5, 4) is (3, 0) there.
const Eigen::Vector2d kRoomCentreMap(3.0, 0.0);

TEST(PlaceCloud, CropsToTheDiscAndTheObstacleBandWithoutAllocating) {
  LocalMapper mapper;
  ASSERT_NO_FATAL_FAILURE(MapTheRoom(2.3, mapper));
  PlaceCloudBuilder builder;
  ASSERT_TRUE(builder.Init({}));
  BoundedVector<Eigen::Vector3f> cloud(builder.config().max_points);
  Status built;
  std::uint64_t allocations = 0;
  {
    test::AllocationScope scope;
    built = builder.Build(mapper, kRoomCentreMap, 4.5f, cloud);
    allocations = scope.allocations();
  }
  ASSERT_TRUE(built.has_value()) << built.error().detail;
  EXPECT_EQ(allocations, 0u);
  ASSERT_GE(cloud.size(), 100u);
  const FreeSpaceGridConfig& band = mapper.config().grid;
  bool wall = false;
  for (const Eigen::Vector3f& p : cloud) {
    EXPECT_LE(p.head<2>().norm(), 4.5f + 1e-3f);
    EXPECT_GE(p.z(), band.obstacle_min_height_m - 0.2f);  // voxel centroids of the band
    EXPECT_LE(p.z(), band.obstacle_max_height_m + 0.2f);
    wall = wall || std::abs(std::abs(p.y()) - 4.0f) < 0.3f;  // the long walls, 4 m from the centre
  }
  EXPECT_TRUE(wall) << "the disc of 4.5 m reaches the long walls";
  // The floor and the ceiling are outside the band: a disc of 3 m in the empty room reaches no
  // wall and holds nothing; nor does a disc nobody mapped.
  EXPECT_FALSE(builder.Build(mapper, kRoomCentreMap, 3.0f, cloud));
  EXPECT_FALSE(builder.Build(mapper, {200.0, 200.0}, 3.0f, cloud));
}

struct Outbox final : CollabOutbox {
  struct Sent {
    CollabMessageType type;
    std::uint16_t to;
    std::vector<std::uint8_t> bytes;
  };
  std::vector<Sent> sent;
  void Send(CollabMessageType type, std::uint16_t to, std::span<const std::uint8_t> bytes) override {
    sent.push_back({type, to, {bytes.begin(), bytes.end()}});
  }
  std::size_t Count(CollabMessageType type) const {
    std::size_t n = 0;
    for (const Sent& s : sent) n += s.type == type ? 1u : 0u;
    return n;
  }
};

std::vector<std::uint8_t> Request(std::uint16_t from, std::uint16_t to, std::uint32_t place) {
  std::vector<std::uint8_t> bytes(kPlaceRequestBytes);
  EXPECT_TRUE(EncodePlaceRequest({from, to, place, kRoomCentreMap.cast<float>(), 5.0f}, bytes));
  return bytes;
}

TEST(CollabSession, AnswersAPlaceRequestOnceAtTheNextExchangeWithinThePeersBudget) {
  LocalMapper mapper;
  ASSERT_NO_FATAL_FAILURE(MapTheRoom(2.3, mapper));
  CollabSessionConfig config;
  config.robot = 1;
  config.max_peers = 2;
  // Room for one cloud of the largest size, not two.
  config.places.budget_bytes_per_peer = PlaceCloudEncodedSize(config.place_cloud.max_points) + 100;
  CollabSession session;
  ASSERT_TRUE(session.Init(config, mapper.config().graph, -mapper.config().base_height_m));
  CollabPublisher publisher;
  ASSERT_TRUE(publisher.Init(config, mapper.config().graph, -mapper.config().base_height_m));
  CollabExchange exchange;
  ASSERT_TRUE(exchange.Init(config));
  Outbox out;
  ASSERT_TRUE(session.Receive(CollabMessageType::kPlaceRequest, Request(2, 1, 7), out));
  EXPECT_EQ(out.Count(CollabMessageType::kPlaceCloud), 0u) << "answered at the next exchange, whose publisher has the map";
  ASSERT_TRUE(PublishNow(mapper, publisher, exchange, session, out));
  ASSERT_EQ(out.Count(CollabMessageType::kPlaceCloud), 1u);
  const Outbox::Sent* answer = nullptr;
  for (const Outbox::Sent& s : out.sent) {
    if (s.type == CollabMessageType::kPlaceCloud) answer = &s;
  }
  ASSERT_NE(answer, nullptr);
  EXPECT_EQ(answer->to, 2);
  BoundedVector<Eigen::Vector3f> points(config.place_cloud.max_points);
  auto h = DecodePlaceCloud(answer->bytes, points);
  ASSERT_TRUE(h);
  EXPECT_EQ(h->robot, 1);
  EXPECT_EQ(h->to, 2);
  EXPECT_EQ(h->place, 7u);
  EXPECT_GE(points.size(), 100u);
  EXPECT_EQ(session.stats().place_requests_served, 1u);

  // The same request again (a retry that crossed the answer): not answered twice.
  out.sent.clear();
  ASSERT_TRUE(session.Receive(CollabMessageType::kPlaceRequest, Request(2, 1, 7), out));
  ASSERT_TRUE(PublishNow(mapper, publisher, exchange, session, out));
  EXPECT_EQ(out.Count(CollabMessageType::kPlaceCloud), 0u);
  // A new place: beyond robot 2's budget, refused and counted.
  ASSERT_TRUE(session.Receive(CollabMessageType::kPlaceRequest, Request(2, 1, 8), out));
  ASSERT_TRUE(PublishNow(mapper, publisher, exchange, session, out));
  EXPECT_EQ(out.Count(CollabMessageType::kPlaceCloud), 0u);
  EXPECT_EQ(session.stats().place_requests_refused, 1u);
  // Another robot's request is not ours to answer; a cloud nobody asked for is refused.
  EXPECT_TRUE(session.Receive(CollabMessageType::kPlaceRequest, Request(2, 3, 9), out));
  ASSERT_TRUE(PublishNow(mapper, publisher, exchange, session, out));
  EXPECT_EQ(out.Count(CollabMessageType::kPlaceCloud), 0u);
  std::vector<std::uint8_t> cloud(PlaceCloudEncodedSize(1));
  const std::vector<Eigen::Vector3f> one{{0, 0, 1}};
  ASSERT_TRUE(EncodePlaceCloud({2, 1, 5, {0, 0}, 0, 0.04f}, one, cloud));
  EXPECT_FALSE(session.Receive(CollabMessageType::kPlaceCloud, cloud, out));
  EXPECT_EQ(session.stats().place_clouds_unsolicited, 1u);
  // A malformed request is refused with a reason and counted.
  std::vector<std::uint8_t> bad = Request(2, 1, 10);
  bad[12] ^= 0x40;
  EXPECT_FALSE(session.Receive(CollabMessageType::kPlaceRequest, bad, out));
  EXPECT_EQ(session.stats().malformed, 1u);
}

TEST(CollabSession, WithTheFallbackOffAPlaceRequestIsRefused) {
  LocalMapper mapper;
  ASSERT_NO_FATAL_FAILURE(MapTheRoom(2.3, mapper));
  CollabSessionConfig config;
  config.robot = 1;
  config.max_peers = 2;
  config.places.budget_bytes_per_peer = 0;
  CollabSession session;
  ASSERT_TRUE(session.Init(config, mapper.config().graph, -mapper.config().base_height_m));
  CollabPublisher publisher;
  ASSERT_TRUE(publisher.Init(config, mapper.config().graph, -mapper.config().base_height_m));
  CollabExchange exchange;
  ASSERT_TRUE(exchange.Init(config));
  Outbox out;
  EXPECT_FALSE(session.Receive(CollabMessageType::kPlaceRequest, Request(2, 1, 7), out));
  ASSERT_TRUE(PublishNow(mapper, publisher, exchange, session, out));
  EXPECT_EQ(out.Count(CollabMessageType::kPlaceCloud), 0u);
  EXPECT_EQ(session.stats().place_requests_refused, 1u);
}

}  // namespace
}  // namespace msgraphs::core
