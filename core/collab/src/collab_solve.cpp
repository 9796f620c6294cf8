// SPDX-License-Identifier: MIT
// The collaborative graph of the merged peers (collaborative_graph.hpp), one update per solve:
// each merged peer's origin starts at its merge (or keeps its estimate when that is the same
// placement); room matches the merge agrees with are tied room to room (corridors across their
// axis only), with their walls wall to wall, and their fine alignments measure the origin
// directly; with fewer than two such rooms (corridors not counted), the walls the merge lays
// on each other tie the maps (wall to wall in the walls modes only). The wall pairs behind the
// priors that feed it all back into the local S-Graph are collected in every mode: feedback is
// its own switch.
#include <cmath>

#include "collab_session_impl.hpp"
#include "msgraphs/core/collab/feedback_gate.hpp"

namespace msgraphs::core {

void CollabSession::Impl::Solve() {
  graph.BeginUpdate();
  wall_pairs.clear();
  stats.graph_refused = 0;
  stats.solve_room_pairs = stats.solve_wall_pairs = stats.solve_origin_measurements = 0;
  stats.solve_room_wall_edges = stats.solve_room_wall_refused = 0;
  const DistilledGraph& mine = own_graph;
  const double cos_pair = std::cos(config.wall_pair_angle_rad);
  // A pair of coinciding walls: tied wall to wall in the walls modes, and in every mode kept for
  // the priors that feed the peer's measurement back into the local S-Graph (PlanePriors), so
  // that the ablation's modes differ in their factors only, and feedback is its own switch
  // (the caller applies the priors or not).
  auto pair_walls = [&](Peer& p, const DistilledWall& A, const DistilledWall& B) {
    if (config.mode.walls) {
      auto wa_node = graph.AddWall(config.robot, A);
      auto wb_node = graph.AddWall(p.robot, B);
      if (!wa_node || !wb_node) return;
      if (graph.AddWallWall(*wa_node, *wb_node)) ++stats.solve_wall_pairs;
    }
    bool known = false;
    for (const SessionWallPair& q : wall_pairs) known = known || (q.own_wall == A.id && q.peer == p.robot && q.peer_wall == B.id);
    if (!known && !wall_pairs.try_push_back({A.id, B.id, p.robot})) ++stats.wall_pairs_refused;
  };
  // Does T lay B on A (same facing, same offset)?
  auto coincide = [&](const Eigen::Isometry3d& T, const DistilledWall& A, const DistilledWall& B) {
    const Eigen::Vector3d n = T.linear() * B.normal;
    const double d = B.d - n.dot(T.translation());
    return n.dot(A.normal) >= cos_pair && std::fabs(d - A.d) <= config.wall_pair_offset_m;
  };
  for (Peer& p : peers) {
    if (!p.used || !p.merged) continue;
    const Eigen::Isometry3d T_merge = p.T_merge.ToIsometry(floor_z_m - PeerFloor(p));
    const Eigen::Isometry3d e = p.T_self_peer.inverse() * T_merge;
    const bool same = p.solved_version > 0 && e.translation().head<2>().norm() < config.anchored_translation_m &&
                      Eigen::AngleAxisd(e.linear()).angle() < config.anchored_rotation_rad;
    if (!graph.SetInitial(p.robot, same ? p.T_self_peer : T_merge)) continue;
    // Both walk one floor (the merge placed them on it): the peer's floor centre at our floor.
    const Eigen::Vector2d floor_xy = p.graph.has_floor ? p.graph.floor_centre : Eigen::Vector2d::Zero();
    static_cast<void>(graph.AddSameFloor(p.robot, Eigen::Vector3d(floor_xy.x(), floor_xy.y(), PeerFloor(p)), floor_z_m,
                                         config.floor_sigma_m));
    for (std::size_t k = 0; k < p.consistent_count; ++k) {
      const RoomMatch& m = p.matches[p.consistent[k]];
      if (m.fine_aligned &&
          graph.AddOriginMeasurement(p.robot, m.T_a_b, config.fine_origin_sigma_m, config.fine_origin_sigma_rad)) {
        ++stats.solve_origin_measurements;
      }
    }
    // Rooms matched by their descriptors (and fine alignment or the merged estimate) that the
    // merge agrees with: room to room, and their walls wall to wall.
    std::size_t room_pairs = 0;
    for (std::size_t k = 0; k < p.consistent_count; ++k) {
      const RoomMatch& m = p.matches[p.consistent[k]];
      const DistilledRoom* ra = mine.FindRoom(m.room_a);
      const DistilledRoom* rb = p.graph.FindRoom(m.room_b);
      if (ra == nullptr || rb == nullptr) continue;
      auto na = graph.AddRoom(config.robot, *ra, floor_z_m);
      auto nb = graph.AddRoom(p.robot, *rb, PeerFloor(p));
      if (!na || !nb || !graph.AddRoomRoom(*na, *nb)) continue;
      // A corridor is tied across its axis only: it does not count towards the two rooms that
      // place a peer without the merge's walls.
      if (ra->shape != RoomShape::kCorridor && rb->shape != RoomShape::kCorridor) ++room_pairs;
      ++stats.solve_room_pairs;
      for (std::int32_t wa : ra->walls) {
        const DistilledWall* A = wa < 0 ? nullptr : mine.FindWall(static_cast<std::uint32_t>(wa));
        if (A == nullptr) continue;
        for (std::int32_t wb : rb->walls) {
          const DistilledWall* B = wb < 0 ? nullptr : p.graph.FindWall(static_cast<std::uint32_t>(wb));
          if (B != nullptr && coincide(m.T_a_b, *A, *B)) pair_walls(p, *A, *B);
        }
      }
    }
    if (room_pairs >= 2) continue;
    if (!config.mode.walls) {
      // Nothing room to room ties it enough: the merge itself measures the origin.
      static_cast<void>(
          graph.AddOriginMeasurement(p.robot, T_merge, config.fine_origin_sigma_m, config.fine_origin_sigma_rad));
    }
    // Too few shared rooms: the walls the merge lays on each other, each peer wall with the own
    // wall it overlaps longest (tied in the walls modes; for the priors in every mode).
    for (const DistilledWall& B : p.graph.walls) {
      const DistilledWall* best = nullptr;
      double best_overlap = config.wall_pair_min_overlap_m;
      const Eigen::Vector2d b0 = p.T_merge * B.a, b1 = p.T_merge * B.b;
      for (const DistilledWall& A : mine.walls) {
        if (!coincide(T_merge, A, B)) continue;
        const Eigen::Vector2d u = (A.b - A.a).normalized();
        const double a0 = 0, a1 = (A.b - A.a).norm();
        const double s0 = u.dot(b0 - A.a), s1 = u.dot(b1 - A.a);
        const double overlap = std::min(a1, std::max(s0, s1)) - std::max(a0, std::min(s0, s1));
        if (overlap > best_overlap) {
          best_overlap = overlap;
          best = &A;
        }
      }
      if (best != nullptr) pair_walls(p, *best, B);
    }
  }
  // Everything else each merged robot mapped is attached too (one factor each: it does not move
  // the estimate, but the graph then holds every robot's walls and rooms in this frame).
  // Each room is tied to its walls (its centre midway between each facing pair, as in the
  // local S-Graph), so that what ties rooms ties their walls too.
  auto attach = [&](std::uint16_t robot, const DistilledGraph& g, double floor) {
    for (const DistilledWall& w : g.walls) stats.graph_refused += graph.AddWall(robot, w) ? 0u : 1u;
    for (const DistilledRoom& r : g.rooms) {
      const auto room = graph.AddRoom(robot, r, floor);
      if (!room) {
        ++stats.graph_refused;
        continue;
      }
      const std::size_t pairs = r.shape == RoomShape::kCorridor ? 1 : 2;
      for (std::size_t k = 0; k < pairs; ++k) {
        const DistilledWall* A = r.walls[2 * k] < 0 ? nullptr : g.FindWall(static_cast<std::uint32_t>(r.walls[2 * k]));
        const DistilledWall* B =
            r.walls[2 * k + 1] < 0 ? nullptr : g.FindWall(static_cast<std::uint32_t>(r.walls[2 * k + 1]));
        if (A == nullptr || B == nullptr) continue;
        const auto wa = graph.AddWall(robot, *A), wb = graph.AddWall(robot, *B);
        if (wa && wb && graph.AddRoomWalls(*room, *wa, *wb))
          ++stats.solve_room_wall_edges;
        else
          ++stats.solve_room_wall_refused;
      }
    }
  };
  bool any_merged = false;
  for (Peer& p : peers) {
    if (!p.used || !p.merged || !graph.has_robot(p.robot)) continue;
    attach(p.robot, p.graph, PeerFloor(p));
    any_merged = true;
  }
  if (any_merged) attach(config.robot, mine, floor_z_m);
  ++stats.solves;
  if (!graph.Solve()) ++stats.solve_failures;
  stats.solve_factors_added += graph.last_update().added;
  stats.solve_factors_kept += graph.last_update().kept;
  stats.solve_factors_removed += graph.last_update().removed;
  solved_version = own_graph.version;
  for (Peer& p : peers) {
    if (!p.used) continue;
    p.solved_version = p.graph.version;
    if (p.merged && graph.has_robot(p.robot)) p.T_self_peer = graph.T_self_robot(p.robot);
  }
}

std::size_t CollabSession::PlanePriors(std::span<PlanePrior> out) const {
  Impl& m = *impl_;
  const DistilledGraph& mine = m.own_graph;
  std::size_t n = 0;
  m.stats.priors_gated = 0;
  for (const SessionWallPair& q : m.wall_pairs) {
    if (n == out.size()) break;
    const Impl::Peer* p = m.FindPeer(q.peer);
    if (p == nullptr || !p->merged) continue;
    const DistilledWall* B = p->graph.FindWall(q.peer_wall);
    if (B == nullptr) continue;
    // The peer's wall in this map frame. For level frames WallBasis turns with the yaw, so the
    // covariance keeps its coordinates.
    const Eigen::Isometry3d& T = p->T_self_peer;
    PlanePrior& prior = out[n];
    prior.plane = q.own_wall;
    prior.normal = (T.linear() * B->normal).normalized();
    prior.d = B->d - prior.normal.dot(T.translation());
    const double fm = m.config.feedback_sigma_floor_m, fr = m.config.feedback_sigma_floor_rad;
    // The peer's own evidence (rumour-free): taken as it is, with the origin's floors.
    prior.covariance = B->covariance;
    prior.covariance.diagonal() += Eigen::Vector3d(fr * fr, fr * fr, fm * fm);
    const DistilledWall* A = mine.FindWall(q.own_wall);
    if (A != nullptr && m.config.feedback_gate_chi2 > 0 && PriorDisagreement(prior, *A) > m.config.feedback_gate_chi2) {
      ++m.stats.priors_gated;
      continue;
    }
    ++n;
  }
  return n;
}

}  // namespace msgraphs::core
