// SPDX-License-Identifier: MIT
// The merge decision's fallback in the session (place_evidence.hpp): serving a peer's place
// requests (taken for the next exchange, whose publisher builds the clouds, and sent when the
// exchange is ingested), holding the place clouds this robot asked for, weighing them in a
// decision the rule left undecided between two transforms, and asking for a new place when the
// held ones cannot tell those two apart.
#include <algorithm>
#include <cmath>

#include "collab_session_impl.hpp"
#include "msgraphs/core/collab/place_decision.hpp"

namespace msgraphs::core {
namespace {

/// Unanswered requests are sent again this many times before the place is given up.
constexpr std::uint32_t kPlaceRetries = 2;

}  // namespace

Status CollabSession::Impl::ReceivePlaceRequest(std::span<const std::uint8_t> bytes) {
  auto q = DecodePlaceRequest(bytes);
  if (!q) {
    ++stats.malformed;
    return q.error();
  }
  if (q->to != config.robot) return Ok();  // another robot's business
  Peer* p = FindOrAddPeer(q->from);
  if (p == nullptr) return Error{Errc::kCapacityExceeded, "collab session: peer store full"};
  const auto t = static_cast<int>(CollabMessageType::kPlaceRequest);
  p->stats.bytes_received[t] += bytes.size();
  ++p->stats.messages_received[t];
  if (config.places.budget_bytes_per_peer == 0) {
    ++stats.place_requests_refused;
    return Error{Errc::kUnsupported, "place request: the fallback is off here"};
  }
  for (const PlaceRequest& held : place_queue) {
    if (held.from == q->from && held.place == q->place) return Ok();  // asked again: once
  }
  if (!place_queue.try_push_back(*q)) {
    ++stats.place_requests_refused;
    return Error{Errc::kCapacityExceeded, "place request: queue full"};
  }
  return Ok();
}

Status CollabSession::Impl::ReceivePlaceCloud(std::span<const std::uint8_t> bytes) {
  auto h = DecodePlaceCloud(bytes, place_scratch);
  if (!h) {
    ++stats.malformed;
    return h.error();
  }
  if (h->to != config.robot) return Ok();
  Peer* p = FindPeer(h->robot);
  if (p == nullptr) return Error{Errc::kNotFound, "place cloud: from an unknown robot"};
  const auto t = static_cast<int>(CollabMessageType::kPlaceCloud);
  p->stats.bytes_received[t] += bytes.size();
  ++p->stats.messages_received[t];
  p->place_bytes_in += bytes.size();
  if (!p->place_pending || h->place != p->place_pending_id) {
    ++stats.place_clouds_unsolicited;
    return Error{Errc::kInvalidArgument, "place cloud: not requested"};
  }
  p->place_pending = false;
  ++stats.place_clouds_received;
  SessionHeldPlace* slot = &p->places[0];
  for (SessionHeldPlace& held : p->places) {
    if (!held.used) {
      slot = &held;
      break;
    }
    if (held.stamp < slot->stamp) slot = &held;
  }
  slot->used = true;
  slot->place = h->place;
  slot->centre_m = h->centre_m.cast<double>();
  slot->stamp = ++place_clock;
  slot->points.clear();
  for (const Eigen::Vector3f& q : place_scratch) slot->points.push_back(q);
  ++p->places_version;
  return Ok();
}

// Requests are taken for the next exchange while `out` has room (the rest stay queued for the
// one after) and this robot's budget for that peer still holds the largest cloud (reserved until
// the exchange is ingested); a retry of a place answered or in flight is not taken again.
void CollabSession::TakePlaceRequests(BoundedVector<PlaceRequest>& out) {
  Impl& m = *impl_;
  const std::size_t largest = PlaceCloudEncodedSize(m.config.place_cloud.max_points);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < m.place_queue.size(); ++i) {
    const PlaceRequest q = m.place_queue[i];
    Impl::Peer* p = m.FindPeer(q.from);
    if (p == nullptr) continue;
    if (p->place_served && p->place_served_id == q.place) continue;  // a retry of one answered
    if (p->place_in_flight && p->place_in_flight_id == q.place) continue;  // taken already
    if (p->place_bytes_out + p->place_bytes_reserved + largest > m.config.places.budget_bytes_per_peer) {
      ++m.stats.place_requests_refused;  // this peer's budget is spent: the request goes unanswered
      continue;
    }
    if (!out.try_push_back(q)) {
      m.place_queue[kept++] = q;  // the next exchange takes it
      continue;
    }
    p->place_bytes_reserved += largest;
    p->place_in_flight = true;
    p->place_in_flight_id = q.place;
  }
  m.place_queue.resize_down(kept);
}

// The taken requests' reservations are released; each is answered (and counted as served) only
// when its cloud goes out.
void CollabSession::Impl::ServePlaces(const CollabExchange& x, bool send, CollabOutbox& out) {
  const std::size_t largest = PlaceCloudEncodedSize(config.place_cloud.max_points);
  for (const CollabExchange::Place& place : x.places) {
    const PlaceRequest& q = place.request;
    Peer* p = FindPeer(q.from);
    if (p == nullptr) continue;
    p->place_bytes_reserved -= std::min<std::uint64_t>(p->place_bytes_reserved, largest);
    if (p->place_in_flight && p->place_in_flight_id == q.place) p->place_in_flight = false;
    if (!send) continue;  // the peer asks again
    const PlaceCloudHeader header{config.robot, q.from, q.place, q.centre_m, static_cast<float>(floor_z_m),
                                  PlaceCloudStep(place.radius_m)};
    auto n = EncodePlaceCloud(header, x.place_points.span().subspan(place.first, place.count), buffer);
    if (!n) {
      ++stats.encode_failures;
      continue;
    }
    p->place_bytes_out += *n;
    p->place_served = true;
    p->place_served_id = q.place;
    ++stats.place_requests_served;
    Send(out, CollabMessageType::kPlaceCloud, q.from, *n);
  }
}

void CollabSession::Impl::WeighPlaces(Peer& p, MergeInputs& in, MergeDecision& d) {
  p.wants_place = false;
  if (config.places.budget_bytes_per_peer == 0 || p.merged) return;
  std::size_t n = 0;
  for (const SessionHeldPlace& held : p.places) {
    if (held.used && !held.points.empty()) place_views[n++] = {held.centre_m, held.points.span()};
  }
  const PlaceDecision pd = DecideWithPlaces(in, search, config.merge, d, std::span(place_views.data(), n),
                                            static_cast<double>(own_free.cell_m()), place_scorer, set_aside);
  stats.place_duels += pd.duels;
  stats.place_set_aside += pd.decision.set_aside;
  d = pd.decision;
  p.wants_place = pd.wants_place;
  p.duel_first = pd.first;
  p.duel_second = pd.second;
}

void CollabSession::Impl::AskForPlace(Peer& p, CollabOutbox& out) {
  const PlaceEvidenceConfig& c = config.places;
  if (c.budget_bytes_per_peer == 0 || p.merged) return;
  auto send = [&](const PlaceRequest& q) {
    auto n = EncodePlaceRequest(q, buffer);
    if (!n) {
      ++stats.encode_failures;
      return false;
    }
    Send(out, CollabMessageType::kPlaceRequest, p.robot, *n);
    ++stats.place_requests_sent;
    p.place_requested_call = calls;
    return true;
  };
  if (p.place_pending) {
    // The peer answers at its next exchange; unanswered, asked again (request_retry_calls).
    if (calls - p.place_requested_call < config.request_retry_calls) return;
    if (p.place_tries >= kPlaceRetries) {
      p.place_pending = false;  // given up: the next undecided decision asks elsewhere
      ++stats.place_requests_unanswered;
      return;
    }
    ++p.place_tries;
    const Eigen::Vector2d& centre = p.places_asked[p.places_asked.size() - 1];
    static_cast<void>(send({config.robot, p.robot, p.place_pending_id, centre.cast<float>(), c.radius_m}));
    return;
  }
  if (!p.wants_place || p.places_asked.full()) return;
  const std::size_t largest = PlaceCloudEncodedSize(config.place_cloud.max_points) + kPlaceRequestBytes;
  if (p.place_bytes_in + largest > c.budget_bytes_per_peer) return;
  const auto centre = place_chooser.Choose(p.walls, p.free, own_free, p.duel_first, p.duel_second, p.places_asked.span(), c);
  if (!centre) return;
  const PlaceRequest q{config.robot, p.robot, ++p.next_place, centre->cast<float>(), c.radius_m};
  if (!send(q)) return;
  p.places_asked.push_back(*centre);
  p.place_pending = true;
  p.place_pending_id = q.place;
  p.place_tries = 0;
}

}  // namespace msgraphs::core
