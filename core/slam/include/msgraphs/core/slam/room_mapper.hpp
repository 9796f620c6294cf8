// SPDX-License-Identifier: MIT
// Rooms, corridors and the floor of the local S-Graph. Periodically (the mapper decides when)
// the free-space grid is segmented with the mapped walls, rooms are detected (core_perception)
// and associated with the mapped ones:
// - a detection is the mapped room (same shape) whose centre is within `match_distance_m`, or
//   that shares at least three (room) / both (corridor) walls; the nearest wins;
// - a matched room whose side now rests on a different wall that is geometrically the same
//   plane gets a wall-to-wall factor between the two (a wall mapped twice);
// - a corridor later seen with both wall pairs becomes a four-wall room (the original kept
//   both, or removed the corridor's vertices by hand);
// - unmatched detections become new rooms; each joins the floor node.
// The floor node is created with the first room, at the rooms' mean centre. Bounded: room and
// pair stores sized at Init; Update allocates in Ceres (the factors it adds); its segmentation
// and detection do not (Rooms.SegmentingAndDetectingAllocateNothing).
#pragma once

#include <cstdint>
#include <vector>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/core/graph/s_graph.hpp"
#include "msgraphs/core/perception/free_space_grid.hpp"
#include "msgraphs/core/perception/room_segmentation.hpp"
#include "msgraphs/core/slam/plane_mapper.hpp"

namespace msgraphs {
class SnapshotReader;
class SnapshotWriter;
}  // namespace msgraphs

namespace msgraphs::core {

struct RoomMapperConfig {
  RoomSegmentationConfig segmentation;
  RoomDetectionConfig detection;
  double match_distance_m = 1.0;  ///< the original's room_dist_threshold
  std::uint32_t min_wall_observations = 2;
  double same_wall_angle_deg = 5.0;  ///< wall-to-wall factor: normals this close
  double same_wall_offset_m = 0.15;  ///< and offsets this close
  Status Validate() const;
};

struct RoomMapperStats {
  std::uint64_t updates = 0, detections = 0, created = 0, matched = 0, upgraded = 0, wall_wall = 0,
                rejected = 0;
  std::uint64_t wall_wall_refused = 0;  ///< the wall-pair memory (4 per room) was full
  /// Updates whose segmentation or detection failed or ran out of capacity (kept what fit).
  std::uint64_t truncated = 0;
};

class RoomMapper {
 public:
  /// Its state in a snapshot (LocalMapper::Save / Load): the reader fails on a store of another
  /// size or a value out of range.
  void Save(SnapshotWriter& w) const;
  void Load(SnapshotReader& r);
  Status Init(const FreeSpaceGridConfig& grid,
              std::size_t max_walls,
              std::size_t max_rooms,
              const RoomMapperConfig& config);

  /// Segments `grid`, detects rooms on the walls `planes` maps, and updates the graph.
  Status Update(const FreeSpaceGrid& grid, const PlaneMapper& planes, SGraph& graph);

  const RoomMapperStats& stats() const { return stats_; }

 private:
  template <class Archive>
  void Io(Archive& ar);
  bool HasWallPair(std::uint32_t a, std::uint32_t b) const;
  void TieSameWalls(SGraph& graph, const MapRoom& mapped, const MapRoom& detected);

  RoomMapperConfig config_;
  RoomSegmenter segmenter_;
  BoundedVector<RoomRegion> regions_;
  BoundedVector<DetectedRoom> detected_;
  BoundedVector<MapWall> walls_;
  BoundedVector<std::uint32_t> wall_ids_;
  BoundedVector<std::uint64_t> wall_pairs_;  // wall-to-wall factors added (a << 32 | b, a < b)
  RoomMapperStats stats_;
};

}  // namespace msgraphs::core
