// SPDX-License-Identifier: MIT
// The own map's two halves (collab_publisher.hpp): the publisher prepares from the local
// S-Graph what the session sends; the session sends it without the map. What an exchange
// carries goes out once, again after ResendAll, never from an exchange older than the last;
// preparing (without marginals) and ingesting allocate nothing.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "alloc_counter.hpp"
#include "mapped_room.hpp"
#include "msgraphs/core/collab/collab_publisher.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/collab/place_messages.hpp"

namespace msgraphs::core {
namespace {

using test::MapTheRoom;

// Counts what is sent, by type, without allocating (the ingest is counted).
struct CountingOutbox final : CollabOutbox {
  std::array<std::size_t, kCollabMessageTypes> sent{};
  void Send(CollabMessageType type, std::uint16_t, std::span<const std::uint8_t>) override {
    ++sent[static_cast<std::size_t>(type)];
  }
  std::size_t operator[](CollabMessageType type) const { return sent[static_cast<std::size_t>(type)]; }
  void Clear() { sent.fill(0); }
};

struct Robot {
  LocalMapper mapper;
  CollabSessionConfig config;
  CollabSession session;
  CollabPublisher publisher;
  CollabExchange exchange;
  void Init(bool marginals) {
    ASSERT_NO_FATAL_FAILURE(MapTheRoom(2.3, mapper));
    config.robot = 1;
    config.max_peers = 2;
    config.distiller.marginal_covariances = marginals;
    const double floor = -mapper.config().base_height_m;
    ASSERT_TRUE(session.Init(config, mapper.config().graph, floor));
    ASSERT_TRUE(publisher.Init(config, mapper.config().graph, floor));
    ASSERT_TRUE(exchange.Init(config));
  }
};

// Robot 2's first exchange (the same map) reaches `r`: a peer must be known for its place
// requests to count.
void IntroducePeer(Robot& r) {
  CollabSessionConfig peer_config = r.config;
  peer_config.robot = 2;
  const double floor = -r.mapper.config().base_height_m;
  CollabSession other;
  ASSERT_TRUE(other.Init(peer_config, r.mapper.config().graph, floor));
  struct Forward final : CollabOutbox {
    CollabSession* to = nullptr;
    void Send(CollabMessageType type, std::uint16_t, std::span<const std::uint8_t> bytes) override {
      CountingOutbox ignore;
      static_cast<void>(to->Receive(type, bytes, ignore));
    }
  } forward;
  forward.to = &r.session;
  CollabPublisher publisher;
  CollabExchange exchange;
  ASSERT_TRUE(publisher.Init(peer_config, r.mapper.config().graph, floor));
  ASSERT_TRUE(exchange.Init(peer_config));
  ASSERT_TRUE(PublishNow(r.mapper, publisher, exchange, other, forward));
}

TEST(CollabPublisher, WhatAnExchangeCarriesGoesOutOnceAndAgainAfterResendAll) {
  Robot r;
  ASSERT_NO_FATAL_FAILURE(r.Init(true));
  CountingOutbox out;
  ASSERT_TRUE(PublishNow(r.mapper, r.publisher, r.exchange, r.session, out));
  EXPECT_EQ(out[CollabMessageType::kDistilledGraph], 1u);
  EXPECT_EQ(out[CollabMessageType::kFreeSpace], 1u);
  EXPECT_EQ(out[CollabMessageType::kRoomDescriptor], 1u) << "the box room";
  EXPECT_EQ(r.publisher.stats().marginal_updates, 1u);
  EXPECT_EQ(r.session.stats().marginal_updates, 1u) << "the publisher's figures reach the session's";
  EXPECT_EQ(r.session.stats().own_rooms, 1u);
  EXPECT_EQ(r.session.distilled().version, r.publisher.graph().version);
  EXPECT_GT(r.session.distilled().walls.size(), 3u);
  EXPECT_FALSE(r.session.free_space().empty()) << "swapped in from the exchange";

  // Nothing changed: nothing rebuilt, nothing sent.
  out.Clear();
  ASSERT_TRUE(PublishNow(r.mapper, r.publisher, r.exchange, r.session, out));
  EXPECT_EQ(r.exchange.rooms.size(), 0u) << "the room's descriptor stands";
  EXPECT_EQ(out[CollabMessageType::kDistilledGraph] + out[CollabMessageType::kRoomDescriptor] +
                out[CollabMessageType::kFreeSpace],
            0u);
  EXPECT_FALSE(r.session.free_space().empty()) << "the summary swapped back is the same map";

  // A peer joined late: everything again, from the session's own copies (nothing rebuilt).
  r.session.ResendAll();
  out.Clear();
  ASSERT_TRUE(PublishNow(r.mapper, r.publisher, r.exchange, r.session, out));
  EXPECT_EQ(r.exchange.rooms.size(), 0u);
  EXPECT_EQ(out[CollabMessageType::kDistilledGraph], 1u);
  EXPECT_EQ(out[CollabMessageType::kFreeSpace], 1u);
  EXPECT_EQ(out[CollabMessageType::kRoomDescriptor], 1u);
}

TEST(CollabPublisher, AnExchangeOlderThanTheLastIsRefused) {
  Robot r;
  ASSERT_NO_FATAL_FAILURE(r.Init(false));
  CountingOutbox out;
  ASSERT_TRUE(PublishNow(r.mapper, r.publisher, r.exchange, r.session, out));
  ASSERT_GE(r.session.distilled().version, 1u);
  CollabExchange stale;
  ASSERT_TRUE(stale.Init(r.config));  // version 0: before everything the session has
  out.Clear();
  EXPECT_FALSE(r.session.Ingest(stale, r.publisher.stats(), out));
  EXPECT_EQ(out[CollabMessageType::kDistilledGraph], 0u);
  EXPECT_GE(r.session.distilled().walls.size(), 4u) << "the session's own map stands";
}

TEST(CollabPublisher, PreparingWithoutMarginalsAndIngestingAllocateNothing) {
  Robot r;
  ASSERT_NO_FATAL_FAILURE(r.Init(false));
  // A peer's place request, taken for the exchange: the place cloud is built in Prepare.
  CountingOutbox out;
  ASSERT_NO_FATAL_FAILURE(IntroducePeer(r));
  ASSERT_EQ(r.session.peers(), 1u);
  std::vector<std::uint8_t> request(kPlaceRequestBytes);
  ASSERT_TRUE(EncodePlaceRequest({2, 1, 7, Eigen::Vector2f(3.0f, 0.0f), 4.5f}, request));
  ASSERT_TRUE(r.session.Receive(CollabMessageType::kPlaceRequest, request, out));

  std::uint64_t take = 0, prepare = 0, ingest = 0;
  {
    test::AllocationScope scope;
    r.exchange.requests.clear();
    r.session.TakePlaceRequests(r.exchange.requests);
    take = scope.allocations();
  }
  ASSERT_EQ(r.exchange.requests.size(), 1u);
  {
    // The peer asks again before the answer went out: taken once, not twice.
    ASSERT_TRUE(r.session.Receive(CollabMessageType::kPlaceRequest, request, out));
    BoundedVector<PlaceRequest> again(8);
    r.session.TakePlaceRequests(again);
    EXPECT_EQ(again.size(), 0u) << "in flight";
  }
  {
    test::AllocationScope scope;
    r.publisher.Prepare(r.mapper, r.exchange);
    prepare = scope.allocations();
  }
  ASSERT_EQ(r.exchange.places.size(), 1u);
  EXPECT_GT(r.exchange.places[0].count, 100u) << "the room's walls around the place";
  ASSERT_EQ(r.exchange.rooms.size(), 1u) << "the room described in this (first) exchange";
  {
    test::AllocationScope scope;
    ASSERT_TRUE(r.session.Ingest(r.exchange, r.publisher.stats(), out));
    ingest = scope.allocations();
  }
  EXPECT_EQ(take, 0u);
  EXPECT_EQ(prepare, 0u);
  EXPECT_EQ(ingest, 0u);
  EXPECT_EQ(out[CollabMessageType::kPlaceCloud], 1u);
  EXPECT_EQ(out[CollabMessageType::kRoomDescriptor], 1u);
  EXPECT_EQ(r.session.stats().place_requests_served, 1u);
  // Answered: a retry that crossed the answer is not taken again.
  ASSERT_TRUE(r.session.Receive(CollabMessageType::kPlaceRequest, request, out));
  BoundedVector<PlaceRequest> retry(8);
  r.session.TakePlaceRequests(retry);
  EXPECT_EQ(retry.size(), 0u);
}

TEST(CollabPublisher, ARequestOfAnExchangeRefusedIsTakenAgain) {
  Robot r;
  ASSERT_NO_FATAL_FAILURE(r.Init(false));
  CountingOutbox out;
  ASSERT_NO_FATAL_FAILURE(IntroducePeer(r));
  ASSERT_TRUE(PublishNow(r.mapper, r.publisher, r.exchange, r.session, out));  // version >= 1
  std::vector<std::uint8_t> request(kPlaceRequestBytes);
  ASSERT_TRUE(EncodePlaceRequest({2, 1, 7, Eigen::Vector2f(3.0f, 0.0f), 4.5f}, request));
  ASSERT_TRUE(r.session.Receive(CollabMessageType::kPlaceRequest, request, out));
  CollabExchange stale;
  ASSERT_TRUE(stale.Init(r.config));
  r.session.TakePlaceRequests(stale.requests);
  ASSERT_EQ(stale.requests.size(), 1u);
  r.publisher.Prepare(r.mapper, stale);
  stale.graph.version = 0;  // out of order
  out.Clear();
  EXPECT_FALSE(r.session.Ingest(stale, r.publisher.stats(), out));
  EXPECT_EQ(out[CollabMessageType::kPlaceCloud], 0u);
  // Released: the peer's retry is taken and answered.
  ASSERT_TRUE(r.session.Receive(CollabMessageType::kPlaceRequest, request, out));
  ASSERT_TRUE(PublishNow(r.mapper, r.publisher, r.exchange, r.session, out));
  EXPECT_EQ(out[CollabMessageType::kPlaceCloud], 1u);
}

}  // namespace
}  // namespace msgraphs::core
