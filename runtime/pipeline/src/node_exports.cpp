// SPDX-License-Identifier: MIT
// The node's map outputs, written once at exit (never on the per-scan path):
// - map.pcd: its own map, every keyframe's stored cloud laid out by the optimised keyframe
//   pose, thinned to one point per 5 cm voxel (binary PCD, for PCL and CloudCompare);
// - collab_graph.csv: the collaborative S-Graph as this robot sees it, in its map frame: every
//   robot's origin, the walls (with their extents) and rooms of itself and of every robot it
//   merged, and the accepted room matches (what tools/eval draws);
// - collab_graph.g2o: the same graph for g2o tools (format in docs/runtime.md);
// - merge_log.csv: every merge decision the session logged, with its evidence and its strongest
//   rival (docs/multi-robot.md, "The merge rule").
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <unordered_set>
#include <vector>

#include "msgraphs/runtime/outputs/merge_log_csv.hpp"
#include "msgraphs/runtime/outputs/pcd_file.hpp"
#include "node_impl.hpp"

namespace msgraphs::runtime {

namespace {

constexpr float kMapVoxelM = 0.05f;

// One element of the exported graph, already in this robot's map frame.
struct ExportWall {
  std::uint16_t robot;
  core::DistilledWall wall;  // normal, d and extent in self's frame
};
struct ExportRoom {
  std::uint16_t robot;
  core::DistilledRoom room;        // centre and yaw in self's frame
  Eigen::Vector3d centre_self;     // on the robot's floor
  Eigen::Vector3d centre_measured;  // in its robot's own frame (the g2o measurement)
};
struct ExportOrigin {
  std::uint16_t robot;
  bool merged;
  Eigen::Isometry3d T_self_robot;
};

core::DistilledWall InFrame(const core::DistilledWall& w, const Eigen::Isometry3d& T) {
  core::DistilledWall out = w;
  out.normal = T.linear() * w.normal;
  out.d = w.d - out.normal.dot(T.translation());  // n.p + d = 0
  out.a = (T * Eigen::Vector3d(w.a.x(), w.a.y(), 0)).head<2>();
  out.b = (T * Eigen::Vector3d(w.b.x(), w.b.y(), 0)).head<2>();
  return out;
}

void PutQuaternion(std::ostream& out, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  out << T.translation().x() << ' ' << T.translation().y() << ' ' << T.translation().z() << ' '
      << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w();
}

// Upper triangle of a diagonal information matrix, as g2o writes it.
void PutDiagonalInformation(std::ostream& out, int n, const double* diagonal) {
  for (int r = 0; r < n; ++r) {
    for (int c = r; c < n; ++c) out << ' ' << (r == c ? diagonal[r] : 0.0);
  }
}

}  // namespace

void Node::Impl::WriteExports() {
  if (config.output_dir.empty()) return;
  namespace fs = std::filesystem;
  const fs::path dir(config.output_dir);
  const core::SGraph& graph = mapper.graph();

  // ---- map.pcd ----
  std::vector<Eigen::Vector3f> map_points;
  std::unordered_set<std::uint64_t> voxels;
  std::size_t keyframes_without_cloud = 0;
  for (std::uint32_t k = 0; k < graph.keyframe_slots(); ++k) {
    if (!graph.keyframe_active(k)) continue;
    const auto cloud = mapper.keyframe_cloud(k);
    if (cloud.empty()) {
      ++keyframes_without_cloud;  // evicted from the bounded store (docs/s-graph.md)
      continue;
    }
    const Eigen::Isometry3f T_map_base = graph.keyframe_pose(k).cast<float>();
    for (const Eigen::Vector3f& p_base : cloud) {
      const Eigen::Vector3f p = T_map_base * p_base;
      if (!p.allFinite()) continue;
      const std::uint64_t key = VoxelKey(p, kMapVoxelM);
      if (voxels.insert(key).second) map_points.push_back(p);
    }
  }
  if (auto s = WritePcd((dir / "map.pcd").string(), map_points); !s) {
    std::fprintf(stderr, "msgraphs_node: cannot write map.pcd: %s\n", s.error().detail);
  }
  // The bounded store keeps a cloud of every place (a cell of cloud_cover().cell_m()), so a
  // keyframe without one is normally covered by another cloud of its place.
  const core::KeyframeCloudStoreStats& store = mapper.clouds().stats();
  if (keyframes_without_cloud > 0) {
    std::fprintf(stderr,
                 "msgraphs_node: map.pcd: %zu keyframes have no stored cloud (the store keeps one "
                 "per place, cells of %.1f m)\n",
                 keyframes_without_cloud, mapper.cloud_cover().cell_m());
  }
  if (store.evicted_uncovered > 0) {
    std::fprintf(stderr,
                 "msgraphs_node: WARNING: the cloud store evicted %llu clouds that were their "
                 "place's only one ([mapping] cloud_store_points too small for the building): "
                 "map.pcd may have holes there\n",
                 static_cast<unsigned long long>(store.evicted_uncovered));
  }

  // ---- the collaborative graph ----
  std::vector<ExportOrigin> origins;
  std::vector<ExportWall> walls;
  std::vector<ExportRoom> rooms;
  std::vector<core::RoomMatch> matches;
  {
    std::lock_guard<std::mutex> lock(session_mutex);
    const std::uint16_t self = config.robot.value;
    origins.push_back({self, true, Eigen::Isometry3d::Identity()});
    auto add_graph = [&](std::uint16_t robot, const core::DistilledGraph& g,
                         const Eigen::Isometry3d& T) {
      for (const core::DistilledWall& w : g.walls) walls.push_back({robot, InFrame(w, T)});
      for (const core::DistilledRoom& r : g.rooms) {
        ExportRoom e{robot, r, {}, Eigen::Vector3d(r.centre.x(), r.centre.y(), g.floor_z_m)};
        e.centre_self = T * e.centre_measured;
        e.room.centre = e.centre_self.head<2>();
        const Eigen::Vector3d x_axis = T.linear() * Eigen::Vector3d(std::cos(r.yaw_rad),
                                                                    std::sin(r.yaw_rad), 0);
        e.room.yaw_rad = std::atan2(x_axis.y(), x_axis.x());
        rooms.push_back(e);
      }
    };
    add_graph(self, session.distilled(), Eigen::Isometry3d::Identity());
    std::vector<core::RoomMatch> scratch(256);
    for (std::size_t i = 0; i < session.peers(); ++i) {
      const core::CollabPeerStats p = session.peer_stats(i);
      const Eigen::Isometry3d T = session.T_self_robot(p.robot);
      origins.push_back({p.robot, p.merged, T});
      if (!p.merged) continue;  // its frame is unknown here: nothing of it can be drawn
      if (const core::DistilledGraph* g = session.peer_graph(p.robot)) add_graph(p.robot, *g, T);
      const std::size_t n = session.ConsistentMatches(p.robot, scratch);
      matches.insert(matches.end(), scratch.begin(), scratch.begin() + static_cast<long>(n));
    }
  }
  auto write = [&](const char* name, auto&& body) {
    const fs::path final_path = dir / name;
    const fs::path temp = final_path.string() + ".tmp";
    {
      std::ofstream out(temp);
      out.precision(9);
      body(out);
      if (!out) {
        std::fprintf(stderr, "msgraphs_node: cannot write %s\n", temp.c_str());
        return;
      }
    }
    std::error_code ec;
    fs::rename(temp, final_path, ec);
  };
  write("merge_log.csv", [&](std::ostream& out) {
    outputs::WriteMergeLogHeader(out, config.robot.value, "seconds since the node started");
    std::lock_guard<std::mutex> lock(session_mutex);
    outputs::WriteMergeLogRows(out, merge_log);
    if (merge_log_dropped > 0) out << "# " << merge_log_dropped << " later decisions not kept\n";
  });
  write("collab_graph.csv", [&](std::ostream& out) {
    out << "# the collaborative S-Graph as robot " << config.robot.value
        << " sees it, in its map frame (m, rad)\n"
           "# origin,robot,merged,x,y,z,qx,qy,qz,qw\n"
           "# wall,robot,id,ax,ay,bx,by,nx,ny,nz,d\n"
           "# room,robot,id,x,y,z,yaw,size_x,size_y,corridor\n"
           "# match,robot_a,room_a,robot_b,room_b\n";
    for (const ExportOrigin& o : origins) {
      const Eigen::Quaterniond q(o.T_self_robot.linear());
      const Eigen::Vector3d& t = o.T_self_robot.translation();
      out << "origin," << o.robot << ',' << (o.merged ? 1 : 0) << ',' << t.x() << ',' << t.y()
          << ',' << t.z() << ',' << q.x() << ',' << q.y() << ',' << q.z() << ',' << q.w() << '\n';
    }
    for (const ExportWall& w : walls) {
      out << "wall," << w.robot << ',' << w.wall.id << ',' << w.wall.a.x() << ',' << w.wall.a.y()
          << ',' << w.wall.b.x() << ',' << w.wall.b.y() << ',' << w.wall.normal.x() << ','
          << w.wall.normal.y() << ',' << w.wall.normal.z() << ',' << w.wall.d << '\n';
    }
    for (const ExportRoom& r : rooms) {
      out << "room," << r.robot << ',' << r.room.id << ',' << r.centre_self.x() << ','
          << r.centre_self.y() << ',' << r.centre_self.z() << ',' << r.room.yaw_rad << ','
          << r.room.size_x_m << ',' << r.room.size_y_m << ','
          << (r.room.shape == core::RoomShape::kCorridor ? 1 : 0) << '\n';
    }
    for (const core::RoomMatch& m : matches) {
      out << "match," << m.robot_a << ',' << m.room_a << ',' << m.robot_b << ',' << m.room_b
          << '\n';
    }
  });

  // g2o: robot origins are SE(3) vertices (ids = robot ids, this robot's fixed); this robot's
  // keyframes follow with odometry-chain edges between consecutive ones; rooms are XYZ points
  // tied to their robot's origin by what that robot measured; an accepted room match is a
  // zero-difference point edge. Walls are VERTEX_PLANE (n, d) with their extents in comments:
  // g2o has no plane edge without a sensor offset vertex, so wall factors are not exported.
  write("collab_graph.g2o", [&](std::ostream& out) {
    const core::CollabSessionConfig& sc = session.config();
    const double room_info = 1.0 / (sc.graph.room_sigma_m * sc.graph.room_sigma_m);
    const double same_info = 1.0 / (sc.graph.room_same_sigma_m * sc.graph.room_same_sigma_m);
    const std::uint32_t kKeyframeBase = 1000, kRoomBase = 1000000, kWallBase = 2000000;
    out << "# msgraphs collaborative S-Graph of robot " << config.robot.value
        << " (its map frame). Vertex ids: robots' origins = robot id; keyframes " << kKeyframeBase
        << "+k; rooms " << kRoomBase << "+i; walls " << kWallBase << "+i\n";
    out << "PARAMS_SE3OFFSET 0 0 0 0 0 0 0 1\n";
    for (const ExportOrigin& o : origins) {
      if (!o.merged) continue;
      out << "VERTEX_SE3:QUAT " << o.robot << ' ';
      PutQuaternion(out, o.T_self_robot);
      out << '\n';
    }
    out << "FIX " << config.robot.value << '\n';
    std::int64_t previous = -1;
    const double chain_info[6] = {1e4, 1e4, 1e4, 1e5, 1e5, 1e5};  // 1 cm, 0.2 deg
    // The chain joins keyframes neighbouring in time (slots are reused: not in slot order).
    for (std::uint32_t k = graph.FirstKeyframe(); k != core::SGraph::kNoKeyframe;
         k = graph.NextKeyframe(k)) {
      out << "VERTEX_SE3:QUAT " << kKeyframeBase + k << ' ';
      PutQuaternion(out, graph.keyframe_pose(k));
      out << '\n';
      if (previous >= 0) {
        const Eigen::Isometry3d delta =
            graph.keyframe_pose(static_cast<std::uint32_t>(previous)).inverse() *
            graph.keyframe_pose(k);
        out << "EDGE_SE3:QUAT " << kKeyframeBase + previous << ' ' << kKeyframeBase + k << ' ';
        PutQuaternion(out, delta);
        PutDiagonalInformation(out, 6, chain_info);
        out << '\n';
      } else {
        out << "EDGE_SE3:QUAT " << config.robot.value << ' ' << kKeyframeBase + k << ' ';
        PutQuaternion(out, graph.keyframe_pose(k));
        PutDiagonalInformation(out, 6, chain_info);
        out << '\n';
      }
      previous = k;
    }
    for (std::size_t i = 0; i < rooms.size(); ++i) {
      const ExportRoom& r = rooms[i];
      const Eigen::Vector3d& p = r.centre_self;
      const Eigen::Vector3d& m = r.centre_measured;
      const double info[3] = {room_info, room_info, room_info};
      out << "# room " << r.room.id << " of robot " << r.robot << "\n";
      out << "VERTEX_TRACKXYZ " << kRoomBase + i << ' ' << p.x() << ' ' << p.y() << ' ' << p.z()
          << '\n';
      out << "EDGE_SE3_TRACKXYZ " << r.robot << ' ' << kRoomBase + i << " 0 " << m.x() << ' '
          << m.y() << ' ' << m.z();
      PutDiagonalInformation(out, 3, info);
      out << '\n';
    }
    auto room_index = [&](std::uint16_t robot, std::uint32_t id) -> std::int64_t {
      for (std::size_t i = 0; i < rooms.size(); ++i) {
        if (rooms[i].robot == robot && rooms[i].room.id == id) return static_cast<std::int64_t>(i);
      }
      return -1;
    };
    for (const core::RoomMatch& m : matches) {
      const std::int64_t a = room_index(m.robot_a, m.room_a), b = room_index(m.robot_b, m.room_b);
      if (a < 0 || b < 0) continue;
      const double info[3] = {same_info, same_info, same_info};
      out << "EDGE_POINTXYZ " << kRoomBase + a << ' ' << kRoomBase + b << " 0 0 0";
      PutDiagonalInformation(out, 3, info);
      out << '\n';
    }
    for (std::size_t i = 0; i < walls.size(); ++i) {
      const ExportWall& w = walls[i];
      out << "# wall " << w.wall.id << " of robot " << w.robot << ", extent (" << w.wall.a.x()
          << ", " << w.wall.a.y() << ") to (" << w.wall.b.x() << ", " << w.wall.b.y() << ")\n";
      out << "VERTEX_PLANE " << kWallBase + i << ' ' << w.wall.normal.x() << ' '
          << w.wall.normal.y() << ' ' << w.wall.normal.z() << ' ' << w.wall.d << " 0 0 0\n";
    }
  });
}

}  // namespace msgraphs::runtime
