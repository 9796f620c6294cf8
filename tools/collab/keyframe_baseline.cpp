// SPDX-License-Identifier: MIT
#include "keyframe_baseline.hpp"

#include <algorithm>
#include <span>
#include <vector>

#include "msgraphs/core/collab/room_descriptor.hpp"
#include "msgraphs/core/collab/room_messages.hpp"

namespace msgraphs::tools::collab {

void ExchangeKeyframes(Mission& mission, Robot& from) {
  KeyframeBaselineState& state = from.baseline;
  const core::SGraph& g = from.mapper.graph();
  const core::ScanContextConfig sc_config{20, 60, 20.0f, 0.5f};  // heights above the floor
  // The keyframes made since the last exchange, in time order: sparsification frees slots and
  // new keyframes take them, so "slots above the last one sent" would miss those.
  for (std::uint32_t k = g.FirstKeyframe(); k != core::SGraph::kNoKeyframe; k = g.NextKeyframe(k)) {
    if (g.keyframe_stamp(k) <= state.last_sent_stamp_s) continue;
    state.last_sent_stamp_s = g.keyframe_stamp(k);
    state.own_keyframes.erase(k);  // a sparsified keyframe's descriptor, if the slot is reused
    const auto cloud = from.mapper.keyframe_cloud(k);
    if (cloud.empty()) continue;
    core::ScanContext& sc = state.own_keyframes[k];
    if (!sc.Build(cloud, sc_config)) {
      state.own_keyframes.erase(k);
      continue;
    }
    auto n = core::EncodeRoomDescriptor({from.id(), k, 0}, sc, mission.buffer);
    if (!n) continue;
    for (auto& to : mission.robots) {
      if (to.get() == &from) continue;
      mission.accounting.Add(kKeyframeDescriptor, from.index, to->index, *n + kKeyframePoseBytes);
      core::ScanContext received;
      if (!core::DecodeRoomDescriptor(std::span(mission.buffer.data(), *n), received)) {
        ++mission.accounting.malformed;
        continue;
      }
      // A reused slot is a new keyframe: it replaces the old one and is tried afresh.
      to->baseline.peer_keyframes[{from.index, k}] = {received, g.keyframe_pose(k)};
      to->baseline.tried_keyframes.erase({from.index, k});
    }
  }
  // Keyframes sparsified since are no longer matched against.
  std::erase_if(state.own_keyframes, [&](const auto& e) { return !g.keyframe_active(e.first); });
}

void MatchKeyframes(Mission& mission, Robot& a) {
  KeyframeBaselineState& state = a.baseline;
  bool changed = false;
  for (const auto& [key, theirs] : state.peer_keyframes) {
    if (!state.tried_keyframes.insert(key).second) continue;
    // The most alike of our keyframes.
    float best = 2.0f, yaw = 0.0f;
    std::uint32_t best_k = 0;
    for (const auto& [k, mine] : state.own_keyframes) {
      const auto sc = core::ScanContextDistance(mine, theirs.first);
      if (sc && sc->distance < best) {
        best = sc->distance;
        yaw = sc->yaw_rad;
        best_k = k;
      }
    }
    if (best > kKeyframeScThreshold) continue;
    ++state.proposals;
    Robot& b = *mission.robots[static_cast<std::size_t>(key.first)];
    mission.accounting.Add(kCloudRequest, a.index, b.index, core::kRoomCloudRequestBytes);
    const auto cloud_b = b.mapper.keyframe_cloud(key.second);
    core::RoomCloudHeader header{b.id(), key.second, 0, mission.cloud_encoding, 0.01f};
    auto n = core::EncodeRoomCloud(header, cloud_b, mission.buffer);
    if (!n) continue;
    mission.accounting.Add(kKeyframeCloud, b.index, a.index, *n);
    if (!core::DecodeRoomCloud(std::span(mission.buffer.data(), *n), mission.decoded_cloud)) {
      ++mission.accounting.malformed;
      continue;
    }
    core::RoomMatch m;
    m.robot_a = a.id();
    m.robot_b = b.id();
    m.room_a = best_k;
    m.room_b = key.second;
    m.sc_distance = best;
    if (!mission.matcher.FineAlign(
            a.mapper.keyframe_cloud(best_k), a.mapper.graph().keyframe_pose(best_k),
            mission.decoded_cloud.span(), theirs.second, static_cast<double>(yaw), m)) {
      ++state.rejected_fine;
      continue;
    }
    state.matches[key.first].push_back(m);
    changed = true;
  }
  if (!changed) return;
  state.collab.BeginUpdate();
  state.rejected_consistency = 0;
  for (auto& [b_index, list] : state.matches) {
    std::vector<std::uint32_t> keep(std::min<std::size_t>(list.size(), 64));
    keep.resize(core::ConsistentMatches(list, mission.matcher.config(), keep));
    state.consistent[b_index] = keep;
    state.rejected_consistency += list.size() - keep.size();
    if (keep.empty()) continue;
    const auto robot_b = static_cast<std::uint16_t>(b_index + 1);
    static_cast<void>(state.collab.SetInitial(robot_b, list[keep[0]].T_a_b));
    for (std::uint32_t i : keep)
      static_cast<void>(state.collab.AddOriginMeasurement(robot_b, list[i].T_a_b, 0.03, 0.005));
  }
  static_cast<void>(state.collab.Solve());
}

}  // namespace msgraphs::tools::collab
