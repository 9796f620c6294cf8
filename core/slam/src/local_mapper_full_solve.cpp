// SPDX-License-Identifier: MIT
// When the mapper's full solve runs (LocalMapperConfig::full_solve_lag_keyframes, docs/s-graph.md).
//
// On the spot (lag 0): after a loop closure and every full_solve_every_keyframes keyframes, on
// the mapper's thread, and the new loop judged by the solved graph (undone by a second solve
// when contradicted).
//
// In the background (lag N): the same keyframes call for it, but the graph is copied into a
// job (SGraph::BeginFullSolve) and the job applied N keyframes later. The schedule counts
// keyframes, never time, so the same keyframes make the same map whoever runs the job and
// whenever: a journal replay rebuilds the live map. A loop closure found meanwhile waits for the
// next job; each is judged by the solve that included it before that solve is applied, and a
// contradicted one is removed and the solve dropped (another begins at once without it), so a
// false loop never reaches the map through a full solve. Until it is judged it is in the graph
// and pulls the local window (Huber 1), as on the spot it would not.
#include "msgraphs/core/slam/local_mapper.hpp"

namespace msgraphs::core {

void LocalMapper::ScheduleFullSolve(bool loop) {
  ++keyframe_count_;
  ++keyframes_since_full_;
  const bool due = loop || keyframes_since_full_ >= config_.full_solve_every_keyframes;
  if (config_.full_solve_lag_keyframes == 0) {
    if (!due) return;
    static_cast<void>(graph_.Solve(SolveKind::kFull));
    ++stats_.full_solves;
    if (loop && loops_.RejectIfContradicted(graph_)) {
      static_cast<void>(graph_.Solve(SolveKind::kFull));  // undo its pull
      ++stats_.full_solves;
    } else if (loop) {
      ++stats_.loop_closures;
    }
    keyframes_since_full_ = 0;
    return;
  }
  if (loop && !pending_loops_.try_push_back(loops_.stats().last_factor)) {
    ++stats_.loops_unchecked;
    ++stats_.loop_closures;
  }
  if (due) {
    full_wanted_ = true;
    keyframes_since_full_ = 0;
  }
  if (full_job_.pending() && keyframe_count_ >= full_apply_at_) ApplyBackgroundSolve();
  // The next job begins at the keyframe's end (EndKeyframe), after its rooms: a snapshot
  // asked for can be taken between the two.
}

void LocalMapper::EndKeyframe() {
  if (snapshot_state_ == SnapshotState::kWanted && !full_job_.pending()) {
    snapshot_result_ = Save(snapshot_out_, snapshot_seal_);
    snapshot_state_ = SnapshotState::kTaken;
  }
  if (config_.full_solve_lag_keyframes > 0 && full_wanted_ && !full_job_.pending())
    BeginBackgroundSolve();
}

void LocalMapper::RequestSnapshot(std::span<std::uint8_t> out, SnapshotSeal seal) {
  snapshot_out_ = out;
  snapshot_seal_ = seal;
  snapshot_state_ = SnapshotState::kWanted;
}

std::optional<Expected<std::size_t>> LocalMapper::TakeSnapshot() {
  if (snapshot_state_ != SnapshotState::kTaken) return std::nullopt;
  snapshot_state_ = SnapshotState::kNone;
  snapshot_out_ = {};
  return snapshot_result_;
}

void LocalMapper::BeginBackgroundSolve() {
  if (!graph_.BeginFullSolve(full_job_)) return;  // never: one job at a time, sized at Init
  ++stats_.full_solves_begun;
  job_loops_.clear();
  for (std::uint32_t f : pending_loops_) static_cast<void>(job_loops_.try_push_back(f));
  pending_loops_.clear();
  full_apply_at_ = keyframe_count_ + config_.full_solve_lag_keyframes;
  full_wanted_ = false;
}

void LocalMapper::ApplyBackgroundSolve() {
  if (!full_job_.done()) ++stats_.full_solves_waited;
  full_job_.Complete();  // runs it here if nobody claimed it, else waits for its runner
  ++stats_.full_solves;
  if (!full_job_.report().usable) {
    // A failed solve judges nothing and is not applied: its loops wait for the next one.
    graph_.DropFullSolve(full_job_);
    ++stats_.full_solves_unusable;
    for (std::uint32_t f : job_loops_)
      if (!pending_loops_.try_push_back(f)) ++stats_.loops_unchecked;
    job_loops_.clear();
    full_wanted_ = true;
    return;
  }
  bool refused = false;
  for (std::uint32_t f : job_loops_) {
    const bool out = loops_.RejectIfContradicted(graph_, f, &full_job_);
    refused = refused || out;
    if (!out && graph_.IsLoopFactor(f)) ++stats_.loop_closures;  // it stands
  }
  job_loops_.clear();
  if (refused) {
    // The solve was pulled by a loop now removed: drop it and solve again without, at once.
    graph_.DropFullSolve(full_job_);
    full_wanted_ = true;
  } else if (graph_.ApplyFullSolve(full_job_)) {
    ++stats_.full_solves_background;
  }
}

}  // namespace msgraphs::core
