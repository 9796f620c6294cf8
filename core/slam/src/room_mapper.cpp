// SPDX-License-Identifier: MIT
#include "msgraphs/core/slam/room_mapper.hpp"
#include "msgraphs/base/snapshot_archive.hpp"

#include <cmath>
#include <numbers>

namespace msgraphs::core {

Status RoomMapperConfig::Validate() const {
  if (auto s = segmentation.Validate(); !s) return s;
  if (auto s = detection.Validate(); !s) return s;
  if (!(match_distance_m > 0) || !(same_wall_angle_deg > 0) || !(same_wall_offset_m > 0)) {
    return Error{Errc::kInvalidConfig, "room mapper: distances and angles must be positive"};
  }
  return Ok();
}

Status RoomMapper::Init(const FreeSpaceGridConfig& grid,
                        std::size_t max_walls,
                        std::size_t max_rooms,
                        const RoomMapperConfig& config) {
  if (auto s = config.Validate(); !s) return s;
  config_ = config;
  if (auto s = segmenter_.Init(grid.width, grid.height, 1024, max_walls); !s) return s;
  regions_.Init(1024);
  detected_.Init(max_rooms);
  walls_.Init(max_walls);
  wall_ids_.Init(max_walls);
  wall_pairs_.Init(4 * max_rooms);
  stats_ = {};
  return Ok();
}

bool RoomMapper::HasWallPair(std::uint32_t a, std::uint32_t b) const {
  const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
  for (std::uint64_t k : wall_pairs_) {
    if (k == key) return true;
  }
  return false;
}

void RoomMapper::TieSameWalls(SGraph& graph, const MapRoom& mapped, const MapRoom& detected) {
  const double cos_same = std::cos(config_.same_wall_angle_deg * std::numbers::pi / 180.0);
  for (std::size_t side = 0; side < 4; ++side) {
    const std::int32_t a = mapped.walls[side], b = detected.walls[side];
    if (a < 0 || b < 0 || a == b) continue;
    const auto ua = static_cast<std::uint32_t>(a), ub = static_cast<std::uint32_t>(b);
    if (HasWallPair(ua, ub)) continue;
    const MapPlane pa = graph.plane(ua), pb = graph.plane(ub);
    if (pa.normal.dot(pb.normal) < cos_same || std::fabs(pa.d - pb.d) > config_.same_wall_offset_m)
      continue;
    // A pair that could not be remembered would be tied again at every update, one more
    // factor each time: refuse it (counted) instead.
    if (wall_pairs_.full()) {
      ++stats_.wall_wall_refused;
      continue;
    }
    if (!graph.AddWallWall(ua, ub)) continue;
    wall_pairs_.push_back((static_cast<std::uint64_t>(std::min(ua, ub)) << 32) | std::max(ua, ub));
    ++stats_.wall_wall;
  }
}

Status RoomMapper::Update(const FreeSpaceGrid& grid, const PlaneMapper& planes, SGraph& graph) {
  ++stats_.updates;
  planes.MapWalls(graph, config_.min_wall_observations, walls_, wall_ids_);
  if (walls_.size() < 2) return Ok();
  // Out of capacity, both keep what fit (the regions, the rooms found so far): counted.
  if (!segmenter_.Segment(grid, config_.segmentation, regions_, walls_.span())) ++stats_.truncated;
  if (!segmenter_.DetectRooms(grid, regions_.span(), walls_.span(), config_.detection, detected_))
    ++stats_.truncated;
  for (const DetectedRoom& d : detected_) {
    ++stats_.detections;
    MapRoom room;
    room.shape = d.kind == RoomKind::kRoom ? RoomShape::kFourWall : RoomShape::kCorridor;
    room.centre = d.centre;
    room.corridor_anchor = d.centre;
    for (std::size_t i = 0; i < 4; ++i) {
      room.walls[i] =
          d.walls[i] < 0
              ? -1
              : static_cast<std::int32_t>(wall_ids_[static_cast<std::size_t>(d.walls[i])]);
    }
    // Nearest mapped room that is the same room.
    std::int64_t best = -1;
    double best_distance = 1e300;
    for (std::uint32_t id = 0; id < graph.room_slots(); ++id) {
      const MapRoom mapped = graph.room(id);
      if (!mapped.active) continue;
      int shared = 0;
      for (std::int32_t w : room.walls) {
        if (w < 0) continue;
        for (std::int32_t v : mapped.walls) shared += (v == w) ? 1 : 0;
      }
      double distance = (mapped.centre - room.centre).norm();
      if (mapped.shape == RoomShape::kCorridor || room.shape == RoomShape::kCorridor) {
        // Corridors are placed across by their walls only: compare across.
        const MapRoom& corridor = mapped.shape == RoomShape::kCorridor ? mapped : room;
        const MapPlane wall =
            graph.plane(static_cast<std::uint32_t>(std::max(corridor.walls[0], 0)));
        const Eigen::Vector2d across = wall.normal.head<2>().normalized();
        distance = std::fabs(across.dot(mapped.centre - room.centre));
      }
      const bool same_walls =
          room.shape == RoomShape::kFourWall && mapped.shape == RoomShape::kFourWall ? shared >= 3
                                                                                     : shared >= 2;
      if ((distance < config_.match_distance_m || same_walls) && distance < best_distance) {
        best = id;
        best_distance = distance;
      }
    }
    if (best < 0) {
      auto id = graph.AddRoom(room);
      if (!id) {
        ++stats_.rejected;
        continue;
      }
      ++stats_.created;
      if (!graph.has_floor()) static_cast<void>(graph.SetFloor(room.centre));
      static_cast<void>(graph.AddFloorRoom(*id));
      continue;
    }
    const auto id = static_cast<std::uint32_t>(best);
    const MapRoom mapped = graph.room(id);
    ++stats_.matched;
    if (mapped.shape == RoomShape::kCorridor && room.shape == RoomShape::kFourWall) {
      // A corridor seen whole: now a four-wall room.
      if (graph.UpdateRoom(id, room)) ++stats_.upgraded;
      continue;
    }
    if (mapped.shape == RoomShape::kFourWall && room.shape == RoomShape::kCorridor)
      continue;  // seen partly
    TieSameWalls(graph, mapped, room);
  }
  return Ok();
}


// The wall pairs already tied; regions, detected rooms and walls are taken afresh each update.
template <class Archive>
void RoomMapper::Io(Archive& ar) {
  std::size_t pairs = wall_pairs_.size();
  IoCount(ar, pairs, wall_pairs_.capacity());
  if (ar.failed()) return;
  if constexpr (Archive::kLoading) {
    wall_pairs_.clear();
    for (std::size_t i = 0; i < pairs; ++i) {
      std::uint64_t k = 0;
      ar(k);
      wall_pairs_.push_back(k);
    }
  } else {
    for (std::uint64_t k : wall_pairs_) ar(k);
  }
  ar(stats_);
}

void RoomMapper::Save(SnapshotWriter& w) const { const_cast<RoomMapper*>(this)->Io(w); }
void RoomMapper::Load(SnapshotReader& r) { Io(r); }

}  // namespace msgraphs::core
