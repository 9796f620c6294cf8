// SPDX-License-Identifier: MIT
// msgraphs_collab: a multi-robot mission (simulator recordings) through the whole Multi S-Graphs
// pipeline in one process, deterministically: every robot's local S-Graph in lock-step by
// mission time; every `--exchange-every-s` each robot distils its graph and sends what changed
// (the real wire encoding, decoded by every peer), plus descriptors of new or changed rooms;
// receivers match rooms by Scan Context, request room clouds for fine alignment (modes with
// "fine"), keep the largest mutually consistent set of matches per robot pair, and solve their
// collaborative graph for the other robots' origins.
//
// At the end it reports, from robot 1's point of view: which robots were merged, the ATE of the
// aggregated trajectory (every merged robot's keyframes in robot 1's frame through the
// estimated origins, one SE(3) alignment to the ground truth), room matches accepted and
// rejected (and how many accepted ones are wrong against the truth), and data exchanged per
// message type. --mode keyframes runs the keyframe-level baseline instead of rooms.
//
//   msgraphs_collab --run DIR [--mode rooms|rooms-fine|rooms-walls|rooms-walls-fine|keyframes]
//                   [--cloud f32|q16] [--exchange-every-s 10] [--out DIR] [--markdown]
//
// --out DIR writes robotN_in_robot1.tum: every merged robot's keyframes in robot 1's frame.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "msgraphs/core/collab/distilled_codec.hpp"
#include "msgraphs/core/collab/distiller.hpp"
#include "msgraphs/core/collab/room_descriptor.hpp"
#include "msgraphs/core/collab/room_matcher.hpp"
#include "msgraphs/core/collab/room_messages.hpp"
#include "msgraphs/core/graph/collaborative_graph.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"
#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/can_odometry/odometry_stream.hpp"
#include "msgraphs/tools/recorded_scans.hpp"
#include "msgraphs/tools/tum.hpp"

namespace {

using namespace msgraphs;
namespace fs = std::filesystem;

// kKeyframes is the baseline: keyframe-level inter-robot loop closure as DiSCo-SLAM and
// Swarm-SLAM exchange it (a Scan Context and the pose of every keyframe; the keyframe cloud on
// request for verification), through the same fine alignment and consistency check.
enum class Mode { kRooms, kRoomsFine, kRoomsWalls, kRoomsWallsFine, kKeyframes };
bool Fine(Mode m) {
  return m == Mode::kRoomsFine || m == Mode::kRoomsWallsFine || m == Mode::kKeyframes;
}
bool Walls(Mode m) { return m == Mode::kRoomsWalls || m == Mode::kRoomsWallsFine; }

enum MessageType {
  kGraph,
  kDescriptor,
  kCloudRequest,
  kCloud,
  kKeyframeDescriptor,
  kKeyframeCloud,
  kMessageTypes
};
const char* kTypeNames[kMessageTypes] = {"distilled graph",      "room descriptors",
                                         "room cloud requests",  "room clouds",
                                         "keyframe descriptors", "keyframe clouds"};
constexpr std::size_t kKeyframePoseBytes = 28;  // a keyframe's pose beside its descriptor (7 x f32)
constexpr float kKeyframeScThreshold = 0.25f;   // keyframe candidates (tighter: many more of them)
constexpr std::size_t kCloudRequestBytes = 16;  // robot, room, version, CRC

struct RoomDescriptorEntry {
  std::uint32_t version = 0;  // the room's version when the descriptor was built
  core::DistilledRoom room;
  core::DistilledRoom room_at_build;
  core::ScanContext descriptor;
};

// A room's descriptor is rebuilt and sent again only when the room changed significantly: other
// walls, or its centre or size moved by more than this (its graph entry follows every 1 cm).
constexpr double kDescriptorResendM = 0.3;
// Once a robot pair holds this many consistent matches, a new candidate is checked against the
// merged estimate instead of by fine alignment: no room cloud needs to cross the radio.
constexpr std::size_t kAnchoredMatches = 3;

bool SignificantlyChanged(const core::DistilledRoom& a, const core::DistilledRoom& b) {
  return a.walls != b.walls || a.shape != b.shape ||
         (a.centre - b.centre).norm() > kDescriptorResendM ||
         std::fabs(a.size_x_m - b.size_x_m) > kDescriptorResendM ||
         std::fabs(a.size_y_m - b.size_y_m) > kDescriptorResendM;
}

struct Robot {
  int index = 0;  // 0-based; robot ids on the wire are index + 1
  std::unique_ptr<tools::RecordedScans> scans;
  std::optional<drivers::can_odometry::CandumpFileReader> candump;
  drivers::can_odometry::OdometryStream odometry =
      drivers::can_odometry::OdometryStream::Create({}).value();
  bool odometry_done = false, scans_done = false;
  const drivers::velodyne::Scan* pending = nullptr;
  double first_stamp = -1;
  core::LocalMapper mapper;
  core::Distiller distiller;
  core::RoomDescriptorBuilder descriptor_builder;
  std::uint32_t sent_version = 0;  // reliable delivery: everyone has what was sent
  // Own room clouds and descriptors, by room id (rebuilt when the room's version changes).
  std::map<std::uint32_t, std::vector<Eigen::Vector3f>> room_clouds;
  std::map<std::uint32_t, RoomDescriptorEntry> own_descriptors;
  // What this robot received from each peer.
  std::map<int, core::DistilledGraph> peer_graphs;
  std::map<std::pair<int, std::uint32_t>, RoomDescriptorEntry> peer_descriptors;
  std::set<std::tuple<int, std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t>> tried;
  std::map<std::tuple<int, std::uint32_t, std::uint32_t>, std::vector<Eigen::Vector3f>>
      peer_clouds;                                      // cache
  std::map<int, std::vector<core::RoomMatch>> matches;  // per peer: accepted by the fine check
  std::uint64_t rejected_anchored = 0, accepted_anchored = 0;
  std::map<int, std::vector<std::uint32_t>> consistent;  // per peer: indices into matches
  core::CollaborativeGraph collab;
  // Baseline: keyframe descriptors (own), and those received with the sender's pose at the time.
  std::uint32_t keyframes_sent = 0;
  std::map<std::uint32_t, core::ScanContext> own_keyframes;
  std::map<std::pair<int, std::uint32_t>, std::pair<core::ScanContext, Eigen::Isometry3d>>
      peer_keyframes;
  std::set<std::pair<int, std::uint32_t>> tried_keyframes;
  std::uint64_t rejected_fine = 0, rejected_consistency = 0;
  std::vector<tools::StampedPose> truth;
};

double Now(const Robot& r) {
  return r.pending == nullptr ? 1e300 : r.pending->end_time.seconds_since_epoch() - r.first_stamp;
}

void Advance(Robot& r) {
  r.pending = r.scans->Next();
  if (r.pending == nullptr)
    r.scans_done = true;
  else if (r.first_stamp < 0)
    r.first_stamp = r.pending->end_time.seconds_since_epoch();
}

void FeedOdometry(Robot& r, double until) {
  drivers::can_odometry::CandumpLine line;
  while (!r.odometry_done && r.mapper.odometry().newest_stamp() < until) {
    auto next = r.candump->Next(line);
    if (!next || !*next) {
      r.odometry_done = true;
      break;
    }
    if (!r.odometry.Add(line.frame, line.stamp)) continue;
    const auto& p = r.odometry.pose();
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() =
        Eigen::Quaterniond(p.T_odom_base.qw, p.T_odom_base.qx, p.T_odom_base.qy, p.T_odom_base.qz)
            .normalized()
            .toRotationMatrix();
    T.translation() << p.T_odom_base.x_m, p.T_odom_base.y_m, p.T_odom_base.z_m;
    static_cast<void>(r.mapper.AddOdometry(p.stamp.seconds_since_epoch(), T));
  }
}

void ProcessScan(Robot& r) {
  static std::vector<Eigen::Vector3f> points;
  static std::vector<float> times;
  points.clear();
  times.clear();
  for (const auto& p : r.pending->points) {
    points.emplace_back(p.x_m, p.y_m, p.z_m);
    times.push_back(static_cast<float>(p.time_offset_ns * 1e-9));
  }
  core::LidarScanView view{points, times, r.pending->start_time.seconds_since_epoch(),
                           r.pending->end_time.seconds_since_epoch()};
  FeedOdometry(r, view.end_s + 0.05);
  static_cast<void>(r.mapper.AddScan(view));
  Advance(r);
}

struct Accounting {
  // bytes[type][from][to]
  std::map<std::tuple<int, int, int>, std::uint64_t> bytes;
  std::uint64_t malformed = 0;
  void Add(MessageType type, int from, int to, std::size_t n) { bytes[{type, from, to}] += n; }
  std::uint64_t Total(int type = -1) const {
    std::uint64_t sum = 0;
    for (const auto& [key, n] : bytes) {
      if (type < 0 || std::get<0>(key) == type) sum += n;
    }
    return sum;
  }
};

struct Mission {
  std::vector<std::unique_ptr<Robot>> robots;
  Mode mode = Mode::kRoomsWallsFine;
  core::CloudEncoding cloud_encoding = core::CloudEncoding::kQuantised16;
  core::RoomMatcher matcher;
  Accounting accounting;
  std::vector<std::uint8_t> buffer = std::vector<std::uint8_t>(8 << 20);
  BoundedVector<Eigen::Vector3f> decoded_cloud{200000}, cloud_scratch{200000};
  core::DistilledGraph delta = [] {  // a received message, decoded before it is merged
    core::DistilledGraph g;
    g.Init(4096, 512);
    return g;
  }();

  // Robot `from` distils and sends what changed; descriptors of new or changed rooms.
  void Exchange(Robot& from) {
    if (mode == Mode::kKeyframes) {
      ExchangeKeyframes(from);
      return;
    }
    from.distiller.Update(from.mapper.graph(), from.mapper.plane_mapper());
    const core::DistilledGraph& g = from.distiller.graph();
    if (g.version > from.sent_version) {
      auto n = core::EncodeDistilled(g, from.sent_version, buffer);
      if (n) {
        for (auto& to : robots) {
          if (to.get() == &from) continue;
          accounting.Add(kGraph, from.index, to->index, *n);
          core::DistilledGraph& copy = PeerCopy(*to, from.index);
          if (!core::DecodeDistilled(std::span(buffer.data(), *n), delta, &copy) ||
              !core::ApplyDistilled(delta, copy)) {
            ++accounting.malformed;
          }
        }
        from.sent_version = g.version;
      }
    }
    for (const core::DistilledRoom& room : g.rooms) {
      auto it = from.own_descriptors.find(room.id);
      if (it != from.own_descriptors.end()) {
        it->second.room = room;  // keep the latest estimate for the frames
        if (!SignificantlyChanged(it->second.room_at_build, room)) continue;
      }
      // New or changed: rebuild the room cloud and descriptor, and send the descriptor.
      RoomDescriptorEntry entry;
      entry.version = room.version;
      entry.room = room;
      entry.room_at_build = room;
      if (!from.descriptor_builder.Build(from.mapper, room, cloud_scratch, entry.descriptor))
        continue;
      from.room_clouds[room.id].assign(cloud_scratch.begin(), cloud_scratch.end());
      from.own_descriptors[room.id] = entry;
      const core::RoomDescriptorHeader header{static_cast<std::uint16_t>(from.index + 1), room.id,
                                              room.version};
      auto n = core::EncodeRoomDescriptor(header, entry.descriptor, buffer);
      if (!n) continue;
      for (auto& to : robots) {
        if (to.get() == &from) continue;
        accounting.Add(kDescriptor, from.index, to->index, *n);
        RoomDescriptorEntry received;
        auto h = core::DecodeRoomDescriptor(std::span(buffer.data(), *n), received.descriptor);
        if (!h) {
          ++accounting.malformed;
          continue;
        }
        received.version = h->version;
        received.room = room;  // the room itself came with the distilled graph
        received.room_at_build = room;
        to->peer_descriptors[{from.index, h->room}] = received;
      }
    }
  }

  core::DistilledGraph& PeerCopy(Robot& at, int peer) {
    auto it = at.peer_graphs.find(peer);
    if (it == at.peer_graphs.end()) {
      it = at.peer_graphs.emplace(peer, core::DistilledGraph{}).first;
      it->second.Init(4096, 512);
    }
    return it->second;
  }

  // Robot `a` looks for matches between its rooms and the rooms it received.
  void ExchangeKeyframes(Robot& from) {
    const core::SGraph& g = from.mapper.graph();
    const core::ScanContextConfig sc_config{20, 60, 20.0f, 0.5f};  // heights above the floor
    for (std::uint32_t k = from.keyframes_sent; k < g.keyframe_slots(); ++k) {
      const auto cloud = from.mapper.keyframe_cloud(k);
      if (cloud.empty()) continue;
      core::ScanContext& sc = from.own_keyframes[k];
      if (!sc.Build(cloud, sc_config)) continue;
      auto n = core::EncodeRoomDescriptor({static_cast<std::uint16_t>(from.index + 1), k, 0}, sc,
                                          buffer);
      if (!n) continue;
      for (auto& to : robots) {
        if (to.get() == &from) continue;
        accounting.Add(kKeyframeDescriptor, from.index, to->index, *n + kKeyframePoseBytes);
        core::ScanContext received;
        if (!core::DecodeRoomDescriptor(std::span(buffer.data(), *n), received)) {
          ++accounting.malformed;
          continue;
        }
        to->peer_keyframes[{from.index, k}] = {received, g.keyframe_pose(k)};
      }
    }
    from.keyframes_sent = static_cast<std::uint32_t>(g.keyframe_slots());
  }

  void MatchKeyframes(Robot& a) {
    bool changed = false;
    for (const auto& [key, theirs] : a.peer_keyframes) {
      if (!a.tried_keyframes.insert(key).second) continue;
      // The most alike of our keyframes.
      float best = 2.0f, yaw = 0.0f;
      std::uint32_t best_k = 0;
      for (const auto& [k, mine] : a.own_keyframes) {
        const auto sc = core::ScanContextDistance(mine, theirs.first);
        if (sc && sc->distance < best) {
          best = sc->distance;
          yaw = sc->yaw_rad;
          best_k = k;
        }
      }
      if (best > kKeyframeScThreshold) continue;
      Robot& b = *robots[static_cast<std::size_t>(key.first)];
      accounting.Add(kCloudRequest, a.index, b.index, kCloudRequestBytes);
      const auto cloud_b = b.mapper.keyframe_cloud(key.second);
      core::RoomCloudHeader header{static_cast<std::uint16_t>(b.index + 1), key.second, 0,
                                   cloud_encoding, 0.01f};
      auto n = core::EncodeRoomCloud(header, cloud_b, buffer);
      if (!n) continue;
      accounting.Add(kKeyframeCloud, b.index, a.index, *n);
      if (!core::DecodeRoomCloud(std::span(buffer.data(), *n), decoded_cloud)) {
        ++accounting.malformed;
        continue;
      }
      core::RoomMatch m;
      m.robot_a = static_cast<std::uint16_t>(a.index + 1);
      m.robot_b = static_cast<std::uint16_t>(b.index + 1);
      m.room_a = best_k;
      m.room_b = key.second;
      m.sc_distance = best;
      if (!matcher.FineAlign(a.mapper.keyframe_cloud(best_k),
                             a.mapper.graph().keyframe_pose(best_k), decoded_cloud.span(),
                             theirs.second, static_cast<double>(yaw), m)) {
        ++a.rejected_fine;
        continue;
      }
      a.matches[key.first].push_back(m);
      changed = true;
    }
    if (changed) Solve(a);
  }

  void Match(Robot& a) {
    if (mode == Mode::kKeyframes) {
      MatchKeyframes(a);
      return;
    }
    bool changed = false;
    for (const auto& [key, theirs] : a.peer_descriptors) {
      const int b_index = key.first;
      Robot& b = *robots[static_cast<std::size_t>(b_index)];
      for (const auto& [room_a_id, mine] : a.own_descriptors) {
        const auto tried_key =
            std::make_tuple(b_index, room_a_id, mine.version, key.second, theirs.version);
        if (a.tried.count(tried_key) != 0) continue;
        a.tried.insert(tried_key);
        const auto sc = core::ScanContextDistance(mine.descriptor, theirs.descriptor, true);
        if (!sc || sc->distance > matcher.config().sc_threshold) continue;
        if (mine.room.shape != theirs.room.shape) continue;
        core::RoomMatch m;
        m.robot_a = static_cast<std::uint16_t>(a.index + 1);
        m.robot_b = static_cast<std::uint16_t>(b.index + 1);
        m.room_a = room_a_id;
        m.room_b = key.second;
        m.sc_distance = sc->distance;
        const double floor_a = -a.mapper.config().base_height_m,
                     floor_b = -b.mapper.config().base_height_m;
        const Eigen::Isometry3d T_ma_ra = core::RoomFrame(mine.room, floor_a);
        const Eigen::Isometry3d T_mb_rb = core::RoomFrame(theirs.room, floor_b);
        const auto robot_b = static_cast<std::uint16_t>(b.index + 1);
        const auto consistent = a.consistent.find(b_index);
        if (consistent != a.consistent.end() && consistent->second.size() >= kAnchoredMatches &&
            a.collab.has_robot(robot_b)) {
          // Anchored pair: the candidate must agree with the merged estimate (up to the room's
          // quarter turns), or it is an identical room elsewhere.
          const Eigen::Isometry3d estimate = a.collab.T_self_robot(robot_b);
          bool agrees = false;
          for (int q = 0; q < 4 && !agrees; ++q) {
            const Eigen::Isometry3d T = core::MatchFromRoomFrames(
                T_ma_ra, T_mb_rb, static_cast<double>(sc->yaw_rad) + q * 1.5707963267948966);
            const Eigen::Isometry3d e = estimate.inverse() * T;
            if (e.translation().head<2>().norm() < 0.5 &&
                Eigen::AngleAxisd(e.linear()).angle() < 0.1) {
              m.T_a_b = T;
              agrees = true;
            }
          }
          if (!agrees) {
            ++a.rejected_anchored;
            continue;
          }
          ++a.accepted_anchored;
        } else if (Fine(mode)) {
          // Request b's room cloud (once per version of it); b answers with it.
          const auto cache_key = std::make_tuple(b_index, key.second, theirs.version);
          auto cached = a.peer_clouds.find(cache_key);
          if (cached == a.peer_clouds.end()) {
            accounting.Add(kCloudRequest, a.index, b.index, kCloudRequestBytes);
            const auto& cloud_b = b.room_clouds[key.second];
            core::RoomCloudHeader header{robot_b, key.second, theirs.version, cloud_encoding,
                                         0.01f};
            auto n = core::EncodeRoomCloud(header, cloud_b, buffer);
            if (!n) continue;
            accounting.Add(kCloud, b.index, a.index, *n);
            if (!core::DecodeRoomCloud(std::span(buffer.data(), *n), decoded_cloud)) {
              ++accounting.malformed;
              continue;
            }
            cached = a.peer_clouds
                         .emplace(cache_key, std::vector<Eigen::Vector3f>(decoded_cloud.begin(),
                                                                          decoded_cloud.end()))
                         .first;
          }
          const auto& cloud_a = a.room_clouds[room_a_id];
          if (!matcher.FineAlign(cloud_a, T_ma_ra, cached->second, T_mb_rb,
                                 static_cast<double>(sc->yaw_rad), m)) {
            ++a.rejected_fine;
            continue;
          }
        } else {
          m.T_a_b = core::MatchFromRoomFrames(T_ma_ra, T_mb_rb, static_cast<double>(sc->yaw_rad));
        }
        a.matches[b_index].push_back(m);
        changed = true;
      }
    }
    if (changed) Solve(a);
  }

  void Solve(Robot& a) {
    a.collab.Clear();
    a.rejected_consistency = 0;
    const core::DistilledGraph& mine = a.distiller.graph();
    for (auto& [b_index, list] : a.matches) {
      std::vector<std::uint32_t> keep(std::min<std::size_t>(list.size(), 64));
      keep.resize(core::ConsistentMatches(list, matcher.config(), keep));
      a.consistent[b_index] = keep;
      a.rejected_consistency += list.size() - keep.size();
      if (keep.empty()) continue;
      const auto robot_b = static_cast<std::uint16_t>(b_index + 1);
      static_cast<void>(a.collab.SetInitial(robot_b, list[keep[0]].T_a_b));
      const core::DistilledGraph& theirs = PeerCopy(a, b_index);
      for (std::uint32_t i : keep) {
        const core::RoomMatch& m = list[i];
        // A fine alignment measured the origin directly, from the clouds themselves.
        if (m.fine_aligned)
          static_cast<void>(a.collab.AddOriginMeasurement(robot_b, m.T_a_b, 0.03, 0.005));
        if (mode == Mode::kKeyframes) continue;  // the baseline has no rooms or walls
        const core::DistilledRoom* ra = nullptr;
        const core::DistilledRoom* rb = nullptr;
        for (const auto& r : mine.rooms) ra = r.id == m.room_a ? &r : ra;
        for (const auto& r : theirs.rooms) rb = r.id == m.room_b ? &r : rb;
        if (ra == nullptr || rb == nullptr) continue;
        static_cast<void>(
            a.collab.AddRoomRoom(robot_b, ra->centre, ra->yaw_rad, rb->centre, rb->yaw_rad));
        if (!Walls(mode)) continue;
        // Pair the two rooms' walls through the match: same facing and offset after T_a_b.
        for (std::int32_t wa : ra->walls) {
          const core::DistilledWall* A =
              wa < 0 ? nullptr : mine.FindWall(static_cast<std::uint32_t>(wa));
          if (A == nullptr) continue;
          for (std::int32_t wb : rb->walls) {
            const core::DistilledWall* B =
                wb < 0 ? nullptr : theirs.FindWall(static_cast<std::uint32_t>(wb));
            if (B == nullptr) continue;
            const Eigen::Vector3d n = m.T_a_b.linear() * B->normal;
            const double d = B->d - n.dot(m.T_a_b.translation());
            if (n.dot(A->normal) > std::cos(0.26) && std::fabs(d - A->d) < 0.3) {
              static_cast<void>(a.collab.AddWallWall(robot_b, *A, *B));
            }
          }
        }
      }
    }
    static_cast<void>(a.collab.Solve());
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string run, out_dir;
  Mission mission;
  double every_s = 10.0;
  bool markdown = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--run" && i + 1 < argc)
      run = argv[++i];
    else if (a == "--exchange-every-s" && i + 1 < argc)
      every_s = std::atof(argv[++i]);
    else if (a == "--markdown")
      markdown = true;
    else if (a == "--out" && i + 1 < argc)
      out_dir = argv[++i];
    else if (a == "--mode" && i + 1 < argc) {
      const std::string m = argv[++i];
      if (m == "rooms")
        mission.mode = Mode::kRooms;
      else if (m == "rooms-fine")
        mission.mode = Mode::kRoomsFine;
      else if (m == "rooms-walls")
        mission.mode = Mode::kRoomsWalls;
      else if (m == "rooms-walls-fine")
        mission.mode = Mode::kRoomsWallsFine;
      else if (m == "keyframes")
        mission.mode = Mode::kKeyframes;
      else {
        std::fprintf(stderr, "collab: unknown mode %s\n", m.c_str());
        return 2;
      }
    } else if (a == "--cloud" && i + 1 < argc) {
      const std::string c = argv[++i];
      mission.cloud_encoding =
          c == "f32" ? core::CloudEncoding::kFloat32 : core::CloudEncoding::kQuantised16;
    } else {
      std::fprintf(stderr,
                   "usage: msgraphs_collab --run DIR [--mode "
                   "rooms|rooms-fine|rooms-walls|rooms-walls-fine|keyframes] "
                   "[--cloud f32|q16] [--exchange-every-s 10] [--out DIR] [--markdown]\n");
      return 2;
    }
  }
  if (run.empty() || !(every_s > 0)) {
    std::fprintf(stderr, "collab: --run DIR is required\n");
    return 2;
  }
  if (!mission.matcher.Init({})) return 1;
  for (int i = 0; i < 10; ++i) {
    const fs::path dir = fs::path(run) / ("robot" + std::to_string(i + 1));
    if (!fs::exists(dir / "velodyne.pcap")) break;
    auto r = std::make_unique<Robot>();
    r->index = i;
    r->scans = tools::RecordedScans::Open((dir / "velodyne.pcap").string());
    auto candump = drivers::can_odometry::CandumpFileReader::Open((dir / "odometry.log").c_str());
    if (!r->scans || !candump) {
      std::fprintf(stderr, "collab: cannot open %s\n", dir.c_str());
      return 1;
    }
    r->candump.emplace(std::move(*candump));
    core::LocalMapperConfig config;
    if (!r->mapper.Init(config) ||
        !r->distiller.Init(static_cast<std::uint16_t>(i + 1), config.graph, {}) ||
        !r->descriptor_builder.Init({}) || !r->collab.Init({})) {
      return 1;
    }
    r->truth = tools::ReadTum((dir / "ground_truth.tum").string());
    Advance(*r);
    mission.robots.push_back(std::move(r));
  }
  if (mission.robots.size() < 2) {
    std::fprintf(stderr, "collab: %s holds fewer than two robots\n", run.c_str());
    return 2;
  }
  const auto t0 = std::chrono::steady_clock::now();
  double next_exchange = every_s;
  for (;;) {
    Robot* next = nullptr;
    for (auto& r : mission.robots) {
      if (!r->scans_done && (next == nullptr || Now(*r) < Now(*next))) next = r.get();
    }
    if (next == nullptr) break;
    const double t = Now(*next);
    if (t >= next_exchange) {
      for (auto& r : mission.robots) mission.Exchange(*r);
      for (auto& r : mission.robots) mission.Match(*r);
      next_exchange += every_s;
    }
    ProcessScan(*next);
  }
  for (auto& r : mission.robots) static_cast<void>(r->mapper.Finish());
  for (auto& r : mission.robots) mission.Exchange(*r);
  for (auto& r : mission.robots) mission.Match(*r);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // ---- evaluation from robot 1 ----
  Robot& self = *mission.robots[0];
  std::vector<Eigen::Isometry3d> T_world_map(mission.robots.size());
  std::vector<tools::StampedPose> aggregated, aggregated_truth;
  std::size_t merged = 1;
  std::uint64_t accepted = 0, wrong = 0;
  for (auto& r : mission.robots) {
    std::vector<tools::StampedPose> kf;
    const core::SGraph& g = r->mapper.graph();
    for (std::uint32_t k = 0; k < g.keyframe_slots(); ++k) {
      if (g.keyframe_active(k)) kf.push_back({g.keyframe_stamp(k), g.keyframe_pose(k)});
    }
    std::sort(kf.begin(), kf.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
    const auto own = tools::ComputeAte(kf, r->truth, 0.006);
    T_world_map[static_cast<std::size_t>(r->index)] = own.T_truth_estimate;
    const bool in =
        r->index == 0 || self.collab.has_robot(static_cast<std::uint16_t>(r->index + 1));
    if (r->index != 0 && in) ++merged;
    if (!in) continue;
    const Eigen::Isometry3d T_1_b =
        r->index == 0 ? Eigen::Isometry3d::Identity()
                      : self.collab.T_self_robot(static_cast<std::uint16_t>(r->index + 1));
    if (!out_dir.empty()) {
      std::vector<tools::StampedPose> in_1;
      for (const auto& p : kf) in_1.push_back({p.t, T_1_b * p.T});
      fs::create_directories(out_dir);
      static_cast<void>(tools::WriteTum(
          (fs::path(out_dir) / ("robot" + std::to_string(r->index + 1) + "_in_robot1.tum"))
              .string(),
          in_1));
    }
    for (const auto& p : kf) {
      // Stamps differ per robot clock: pair each keyframe with its own robot's truth here.
      if (const tools::StampedPose* t = tools::Nearest(r->truth, p.t, 0.006)) {
        const double stamp = static_cast<double>(aggregated.size());
        aggregated.push_back({stamp, T_1_b * p.T});
        aggregated_truth.push_back({stamp, t->T});
      }
    }
  }
  // Accepted matches (consistent sets) of every robot, checked against the truth.
  for (auto& r : mission.robots) {
    for (const auto& [b_index, keep] : r->consistent) {
      for (std::uint32_t i : keep) {
        const core::RoomMatch& m = r->matches[b_index][i];
        const Eigen::Isometry3d truth = T_world_map[static_cast<std::size_t>(r->index)].inverse() *
                                        T_world_map[static_cast<std::size_t>(b_index)];
        const Eigen::Isometry3d e = truth.inverse() * m.T_a_b;
        ++accepted;
        if (e.translation().head<2>().norm() > 0.5 || Eigen::AngleAxisd(e.linear()).angle() > 0.1)
          ++wrong;
      }
    }
  }
  std::uint64_t proposed = 0, rejected_fine = 0, rejected_consistency = 0, rejected_anchored = 0,
                accepted_anchored = 0;
  for (auto& r : mission.robots) {
    for (const auto& [b, list] : r->matches) proposed += list.size();
    rejected_fine += r->rejected_fine;
    rejected_consistency += r->rejected_consistency;
    rejected_anchored += r->rejected_anchored;
    accepted_anchored += r->accepted_anchored;
  }
  const auto ate = tools::ComputeAte(aggregated, aggregated_truth, 0.5);
  const char* mode_names[] = {"Rooms", "Rooms + fine alignment", "Rooms and walls",
                              "Rooms and walls + fine alignment", "Keyframes (baseline)"};
  const double mb = static_cast<double>(mission.accounting.Total()) / 1e6;
  if (markdown) {
    std::printf("| %s | %zu | %s | %zu / %zu | %.3f | %.3f | %llu / %llu | %llu |\n", run.c_str(),
                mission.robots.size(), mode_names[static_cast<int>(mission.mode)], merged,
                mission.robots.size(), ate.rmse, mb,
                static_cast<unsigned long long>(accepted - wrong),
                static_cast<unsigned long long>(accepted), static_cast<unsigned long long>(wrong));
    return 0;
  }
  std::printf("mission %s: %zu robots, mode %s, %.1f s\n", run.c_str(), mission.robots.size(),
              mode_names[static_cast<int>(mission.mode)], seconds);
  std::printf(
      "robot 1 merged %zu of %zu robots; aggregated ATE %.3f m over %zu keyframes (max %.3f m)\n",
      merged, mission.robots.size(), ate.rmse, ate.poses, ate.max);
  for (auto& r : mission.robots) {
    if (r->index == 0) continue;
    const auto robot = static_cast<std::uint16_t>(r->index + 1);
    if (!self.collab.has_robot(robot)) {
      std::printf("  robot %d: not merged\n", r->index + 1);
      continue;
    }
    const Eigen::Isometry3d truth =
        T_world_map[0].inverse() * T_world_map[static_cast<std::size_t>(r->index)];
    const Eigen::Isometry3d e = truth.inverse() * self.collab.T_self_robot(robot);
    std::printf("  robot %d: origin error %.3f m, %.2f deg (%zu factors)\n", r->index + 1,
                e.translation().head<2>().norm(),
                Eigen::AngleAxisd(e.linear()).angle() * 180.0 / 3.14159265358979,
                self.collab.factors(robot));
  }
  std::printf(
      "room matches (all robots): %llu proposed by Scan Context, %llu rejected by fine alignment, "
      "%llu checked "
      "against a merged estimate (%llu rejected), %llu rejected by the consistency check, %llu "
      "accepted, %llu of them "
      "wrong against the truth\n",
      static_cast<unsigned long long>(proposed + rejected_fine + rejected_anchored),
      static_cast<unsigned long long>(rejected_fine),
      static_cast<unsigned long long>(accepted_anchored + rejected_anchored),
      static_cast<unsigned long long>(rejected_anchored),
      static_cast<unsigned long long>(rejected_consistency),
      static_cast<unsigned long long>(accepted), static_cast<unsigned long long>(wrong));
  std::printf("data exchanged: %.3f MB in total, %llu messages malformed\n", mb,
              static_cast<unsigned long long>(mission.accounting.malformed));
  for (int t = 0; t < kMessageTypes; ++t) {
    std::printf("  %-20s %10.1f kB\n", kTypeNames[t],
                static_cast<double>(mission.accounting.Total(t)) / 1e3);
  }
  for (const auto& from : mission.robots) {
    for (const auto& to : mission.robots) {
      if (from == to) continue;
      std::uint64_t sum = 0;
      for (const auto& [key, n] : mission.accounting.bytes) {
        if (std::get<1>(key) == from->index && std::get<2>(key) == to->index) sum += n;
      }
      std::printf("  robot %d -> robot %d %10.1f kB\n", from->index + 1, to->index + 1,
                  static_cast<double>(sum) / 1e3);
    }
  }
  return 0;
}
