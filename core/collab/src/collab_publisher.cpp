// SPDX-License-Identifier: MIT
#include "msgraphs/core/collab/collab_publisher.hpp"

#include <algorithm>
#include <cmath>

namespace msgraphs::core {
namespace {

bool SignificantlyChanged(const DistilledRoom& a, const DistilledRoom& b, double threshold_m) {
  return a.walls != b.walls || a.shape != b.shape || (a.centre - b.centre).norm() > threshold_m ||
         std::fabs(a.size_x_m - b.size_x_m) > threshold_m ||
         std::fabs(a.size_y_m - b.size_y_m) > threshold_m;
}

}  // namespace

Status CollabExchange::Init(const CollabSessionConfig& config) {
  graph.Init(config.distiller.max_walls, config.distiller.max_rooms);
  if (auto s = free.Init(config.free_space); !s) return s;
  rooms.Init(config.rooms_per_exchange);
  room_points.Init(config.room_points_per_exchange);
  places.Init(config.places.max_requests_queued);
  requests.Init(config.places.max_requests_queued);
  place_points.Init(config.places.max_requests_queued * config.place_cloud.max_points);
  Clear();
  return Ok();
}

void CollabExchange::Clear() {
  graph_changed = free_built = false;
  rooms.clear();
  room_points.clear();
  places.clear();
  place_points.clear();
}

Status CollabPublisher::Init(const CollabSessionConfig& config_in,
                             const SGraphConfig& graph,
                             double floor_z_map_m) {
  CollabSessionConfig config = config_in;
  config.distiller.floor_z_m = floor_z_map_m;
  if (auto s = config.Validate(); !s) return s;
  if (!std::isfinite(floor_z_map_m))
    return Error{Errc::kInvalidConfig, "collab publisher: floor height not finite"};
  config_ = config;
  floor_z_m_ = floor_z_map_m;
  if (auto s = distiller_.Init(config.robot, graph, config.distiller); !s) return s;
  // The builder thins a room's cloud to what the store holds: a hall is described, never refused.
  RoomDescriptorConfig descriptor = config.descriptor;
  descriptor.max_cloud_points = config.max_room_points;
  if (auto s = builder_.Init(descriptor); !s) return s;
  if (auto s = place_builder_.Init(config.place_cloud); !s) return s;
  built_.assign(config.max_rooms, Built{});
  cloud_scratch_.Init(config.descriptor.max_points);
  place_scratch_.Init(config.place_cloud.max_points);
  stats_ = {};
  return Ok();
}

void CollabPublisher::Prepare(const LocalMapper& mapper,
                              CollabExchange& out,
                              MarginalsTiming marginals) {
  out.Clear();
  ++stats_.prepares;
  out.graph_changed = distiller_.Update(mapper.graph(), mapper.plane_mapper(), marginals);
  const Distiller::Stats& d = distiller_.stats();
  stats_.marginal_updates = d.marginal_updates;
  stats_.marginal_failures = d.marginal_failures;
  stats_.marginals_run_at_prepare = d.marginals_run_at_update;
  stats_.marginals_not_ready = d.marginals_not_ready;
  stats_.walls_awaiting_marginals = d.walls_awaiting_marginals;
  stats_.own_evidence_jobs = d.own_evidence_jobs;
  stats_.own_solve_failures = d.own_solve_failures;
  stats_.own_solve_unconverged = d.own_solve_unconverged;
  stats_.walls_awaiting_estimates = d.walls_awaiting_estimates;
  stats_.rooms_awaiting_estimates = d.rooms_awaiting_estimates;
  stats_.walls_unobserved = d.walls_unobserved;
  const DistilledGraph& g = distiller_.graph();
  out.graph.CopyFrom(g);  // capacities sized alike

  out.free_built = static_cast<bool>(out.free.Build(mapper.grid(), g.walls.span()));
  if (!out.free_built) ++stats_.free_space_build_failures;

  for (const PlaceRequest& q : out.requests) {
    if (out.places.full()) break;  // sized for the session's queue: not reached
    CollabExchange::Place place;
    place.request = q;
    place.radius_m = std::min(q.radius_m, config_.places.radius_m);
    place.first = out.place_points.size();
    // Nothing stored there (a place never reached, or its clouds evicted): an empty cloud says so.
    if (place_builder_.Build(mapper, q.centre_m.cast<double>(), place.radius_m, place_scratch_)) {
      for (const Eigen::Vector3f& p : place_scratch_) {
        if (!out.place_points.try_push_back(p)) break;
      }
    }
    place.count = out.place_points.size() - place.first;
    out.places.push_back(place);
    ++stats_.places_built;
  }
  PrepareRooms(mapper, out);
}

void CollabPublisher::PrepareRooms(const LocalMapper& mapper, CollabExchange& out) {
  for (const DistilledRoom& room : distiller_.graph().rooms) {
    Built* slot = nullptr;
    for (Built& b : built_) {
      if (b.used && b.id == room.id) {
        slot = &b;
        break;
      }
    }
    if (slot != nullptr) {
      if (SignificantlyChanged(slot->at_build, room, config_.descriptor_resend_m)) slot->stale = true;
    } else {
      for (Built& b : built_) {
        if (b.used) continue;
        slot = &b;
        break;
      }
      if (slot == nullptr) {
        ++stats_.rooms_refused;
        continue;
      }
      slot->stale = true;
    }
    if (!slot->stale) continue;
    if (out.rooms.full() ||
        out.room_points.size() + config_.max_room_points > out.room_points.capacity()) {
      ++stats_.rooms_deferred;  // stays stale: built at the next exchange
      continue;
    }
    if (!builder_.Build(mapper, room, cloud_scratch_, descriptor_scratch_)) continue;
    stats_.room_points_peak = std::max(stats_.room_points_peak, cloud_scratch_.size());
    if (cloud_scratch_.size() > config_.max_room_points) {
      ++stats_.room_clouds_too_large;
      continue;
    }
    slot->used = true;
    slot->stale = false;
    slot->id = room.id;
    slot->version = std::max<std::uint32_t>(room.version, 1);
    slot->at_build = room;
    out.rooms.push_back(CollabExchange::Room{});
    CollabExchange::Room& e = out.rooms[out.rooms.size() - 1];
    e.id = room.id;
    e.version = slot->version;
    e.at_build = room;
    e.descriptor = descriptor_scratch_;
    e.first = out.room_points.size();
    for (const Eigen::Vector3f& p : cloud_scratch_) out.room_points.push_back(p);
    e.count = cloud_scratch_.size();
  }
}

Status PublishNow(const LocalMapper& mapper,
                  CollabPublisher& publisher,
                  CollabExchange& exchange,
                  CollabSession& session,
                  CollabOutbox& out,
                  MarginalsTiming marginals) {
  exchange.requests.clear();
  session.TakePlaceRequests(exchange.requests);
  publisher.Prepare(mapper, exchange, marginals);
  return session.Ingest(exchange, publisher.stats(), out);
}

}  // namespace msgraphs::core
