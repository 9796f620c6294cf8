// SPDX-License-Identifier: MIT
// The mapper's snapshot (LocalMapper::Save / Load, docs/s-graph.md "Snapshots").
//
// Taken between two scans, after a keyframe: what persists from one keyframe to the next is
// saved (the graph's own snapshot, the odometry, the cloud store, the loop closer's descriptors,
// the free-space grid, the plane extents, the wall pairs, the fitness gate, the mapper's
// scalars and counters); what each scan or keyframe rebuilds is not (the scan buffers, the
// trees, the matcher's workspace). The local map is rebuilt at load from the stored clouds and
// the graph, as the keyframe that ended before the snapshot built it.
//
// Layout: magic, version, payload length, payload CRC-32; the payload holds the graph's
// snapshot (with its own header and CRC) behind its length, then the parts.
#include <cstring>

#include "msgraphs/base/snapshot_archive.hpp"
#include "msgraphs/base/snapshot_header.hpp"
#include "msgraphs/core/slam/local_mapper.hpp"

namespace msgraphs::core {
namespace {

constexpr SnapshotMagic kMagic{'M', 'S', 'G', 'L', 'M', 'A', 'P', 'R'};
constexpr std::uint32_t kVersion = 2;  // 2: config-derived values no longer in it
constexpr std::size_t kHeaderBytes = kSnapshotHeaderBytes;

template <class Archive>
void IoPose(Archive& ar, Eigen::Isometry3d& T) {
  ar(T.matrix().data(), 16);
}

// A bounded list: its length, then its entries.
template <class Archive, typename T>
void IoBounded(Archive& ar, BoundedVector<T>& list) {
  std::size_t n = list.size();
  IoCount(ar, n, list.capacity());
  if (ar.failed()) return;
  if constexpr (Archive::kLoading) {
    list.clear();
    for (std::size_t i = 0; i < n; ++i) {
      T v{};
      ar(v);
      list.push_back(v);
    }
  } else {
    for (const T& v : list) ar(v);
  }
}

}  // namespace

// The mapper's own fields (the parts write themselves).
template <class Archive>
void LocalMapper::Io(Archive& ar) {
  IoBool(ar, last_match_.attempted);
  ar(last_match_.from_s);
  ar(last_match_.to_s);
  // The result is one of ToString's names (or "none"): saved as its outcome's number.
  std::uint8_t result = 0;  // "none"
  for (std::uint8_t o = 0; o < 5; ++o)
    if (std::strcmp(last_match_.result, ToString(static_cast<MatchOutcome>(o))) == 0) result = o + 1;
  ar(result);
  if constexpr (Archive::kLoading) {
    if (result > 5) ar.Fail();
    last_match_.result = result == 0 || result > 5 ? "none" : ToString(static_cast<MatchOutcome>(result - 1));
  }
  IoBool(ar, last_match_.motion_seeded);
  ar(last_match_.fitness_m2);
  ar(last_match_.limit_m2);
  IoPose(ar, last_match_.T_from_to);
  ar(fitness_limit_m2_);
  IoSameSize(ar, sequence_.size());
  if (ar.failed()) return;
  ar(sequence_.data(), sequence_.size());
  for (Eigen::Isometry3d& T : keyframe_odometry_) IoPose(ar, T);
  IoBounded(ar, prior_factors_);
  IoBool(ar, have_track_);
  IoPose(ar, track_T_last_base_);
  IoPose(ar, track_T_odom_);
  ar(untracked_sweeps_);
  IoPose(ar, keyframe_motion_.T_last_new);
  IoBool(ar, keyframe_motion_.tracked);
  ar(next_sequence_);
  IoBool(ar, have_keyframe_);
  ar(last_keyframe_);
  IoPose(ar, last_odometry_);
  IoPose(ar, T_map_odom_);
  ar(path_m_);
  ar(motion_m_);
  ar(motion_s_);
  ar(motion_end_s_);
  ar(keyframes_since_rooms_);
  ar(keyframes_since_full_);
  ar(keyframe_count_);
  ar(full_apply_at_);
  IoBool(ar, full_wanted_);
  IoBounded(ar, pending_loops_);
  IoBounded(ar, job_loops_);
  ar(stats_);
}

std::size_t LocalMapper::SnapshotBytes() const {
  const LocalMapperConfig& c = config_;
  const std::size_t slots = c.graph.max_keyframes + 1;
  const std::size_t cells =
      static_cast<std::size_t>(c.grid.width) * static_cast<std::size_t>(c.grid.height);
  const std::size_t descriptor =
      static_cast<std::size_t>(c.loops.scan_context.rings * c.loops.scan_context.sectors);
  // Each part's stores at their fullest, with room for the counters and sizes around them.
  constexpr std::size_t kSlack = 4096;
  return kHeaderBytes + 8 + graph_.SnapshotBytes() +                               // the graph
         c.odometry_capacity * (8 + 128) + kSlack +                                 // odometry
         c.cloud_store_points * 12 + slots * 33 + (2 * slots + 1) * 12 + kSlack +   // clouds
         c.graph.max_planes * 49 + kSlack +                                         // extents
         4 * c.graph.max_rooms * 8 + kSlack +                                       // wall pairs
         slots * (17 + 4 * descriptor) + kSlack +                                   // descriptors
         cells * 7 + kSlack +                                                       // free space
         c.scan_match_fitness_gate().window * 8 + kSlack +                          // the gate
         slots * (8 + 128) + (c.max_plane_priors + 2 * kLoopChecks) * 4 + kSlack;  // the mapper
}

Status LocalMapper::SealSnapshot(std::span<std::uint8_t> snapshot) {
  // The graph's snapshot sits behind the mapper's header and its length; the mapper's CRC
  // covers the graph's, so the graph's is written first. Everything is checked before either.
  auto payload_bytes = SnapshotPayloadBytes(snapshot, kMagic);
  if (!payload_bytes) return payload_bytes.error();
  const auto payload = snapshot.subspan(kHeaderBytes, *payload_bytes);
  std::uint64_t graph_bytes = 0;
  SnapshotReader length(payload);
  length(graph_bytes);
  if (length.failed() || graph_bytes > payload.size() - 8)
    return Error{Errc::kInvalidArgument, "mapper snapshot: the graph's length runs past its end"};
  if (Status s = SGraph::SealSnapshot(payload.subspan(8, static_cast<std::size_t>(graph_bytes))); !s) return s;
  return SealSnapshotHeader(snapshot, kMagic);
}

Expected<std::size_t> LocalMapper::Save(std::span<std::uint8_t> out, SnapshotSeal seal) const {
  if (full_job_.pending())
    return Error{Errc::kWouldBlock, "a background solve is pending: save after it is applied"};
  if (out.size() < kHeaderBytes + 8)
    return Error{Errc::kCapacityExceeded, "snapshot buffer too small"};
  // The graph's snapshot behind its length.
  auto graph_bytes = graph_.Save(out.subspan(kHeaderBytes + 8), seal);
  if (!graph_bytes) return graph_bytes.error();
  SnapshotWriter length(out.subspan(kHeaderBytes, 8));
  length(static_cast<std::uint64_t>(*graph_bytes));
  const std::size_t parts_at = kHeaderBytes + 8 + *graph_bytes;
  SnapshotWriter w(out.subspan(parts_at));
  odometry_.Save(w);
  clouds_.Save(w);
  cover_.Save(w);
  planes_mapper_.Save(w);
  rooms_.Save(w);
  loops_.Save(w);
  grid_.Save(w);
  fitness_gate_.Save(w);
  const_cast<LocalMapper*>(this)->Io(w);
  if (w.failed()) return Error{Errc::kCapacityExceeded, "snapshot buffer too small"};
  return WriteSnapshotHeader(out, kMagic, kVersion, 8 + *graph_bytes + w.size(), seal);
}

Status LocalMapper::Load(std::span<const std::uint8_t> in) {
  if (full_job_.pending())
    return Error{Errc::kWouldBlock, "a background solve is pending"};
  auto checked = SnapshotPayload(in, kMagic, kVersion);
  if (!checked) return checked.error();
  const std::span<const std::uint8_t> payload = *checked;
  std::uint64_t graph_bytes = 0;
  SnapshotReader length(payload);
  length(graph_bytes);
  if (length.failed() || graph_bytes > payload.size() - 8)
    return Error{Errc::kInvalidArgument, "mapper snapshot: the graph's length runs past its end"};
  // The graph first: it refuses a snapshot of another config and then changes nothing.
  const std::uint64_t revision_before = graph_.stats().revision;
  if (auto s = graph_.Load(payload.subspan(8, static_cast<std::size_t>(graph_bytes))); !s) {
    // A graph left empty by records that did not hold together (its revision moved): the
    // mapper follows it.
    if (graph_.stats().revision != revision_before) static_cast<void>(Init(config_));
    return s;
  }
  const auto fail = [this](const char* why) -> Status {
    static_cast<void>(Init(config_));
    return Error{Errc::kInvalidArgument, why};
  };
  SnapshotReader r(payload.subspan(8 + static_cast<std::size_t>(graph_bytes)));
  odometry_.Load(r);
  clouds_.Load(r);
  cover_.Load(r);
  planes_mapper_.Load(r);
  rooms_.Load(r);
  loops_.Load(r);
  grid_.Load(r);
  fitness_gate_.Load(r);
  Io(r);
  if (r.failed() || r.remaining() != 0) return fail("mapper snapshot: parts do not fit this mapper");
  if (have_keyframe_ && !graph_.keyframe_active(last_keyframe_))
    return fail("mapper snapshot: its last keyframe is not in its graph");
  // Factor ids the mapper acts on later: its priors are removed by id (a wrong id would take
  // another factor out). Pending loops are judged by id, and an id that no longer names a loop
  // (sparsified meanwhile) is skipped there. No job is pending, so no loop is in one.
  for (std::uint32_t f : prior_factors_)
    if (!graph_.IsPlanePriorFactor(f)) return fail("mapper snapshot: a prior id names no prior");
  if (!job_loops_.empty()) return fail("mapper snapshot: loops of a solve that is not pending");
  // What each scan rebuilds: nothing prepared, the local map of the last keyframe built as
  // the keyframe before the snapshot built it.
  prepared_ = false;
  local_map_keyframe_ = local_map_failed_ = kNoKeyframe;
  if (config_.track_scans) static_cast<void>(EnsureLocalMap());
  snapshot_state_ = SnapshotState::kNone;
  snapshot_out_ = {};
  // A snapshot taken at a keyframe's end (RequestSnapshot) comes before the solve that keyframe
  // wanted began: it begins here, as it did there.
  if (config_.full_solve_lag_keyframes > 0 && full_wanted_) BeginBackgroundSolve();
  return Ok();
}

}  // namespace msgraphs::core
