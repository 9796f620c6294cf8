// SPDX-License-Identifier: MIT
// The keyframe-level baseline (--mode keyframes): inter-robot loop closure at keyframe level, as
// DiSCo-SLAM and Swarm-SLAM exchange it. Every keyframe's Scan Context (the room descriptor's
// 1.2 kB message) and its pose go to every peer; a received keyframe whose nearest own keyframe
// is within kKeyframeScThreshold triggers a request for its cloud, then the same fine alignment,
// consistency check and origin factors as the room-based algorithm. Bytes are counted as if the
// messages crossed the radio.
#pragma once

#include <cstddef>

#include "mission.hpp"
#include "robot.hpp"

namespace msgraphs::tools::collab {

/// A keyframe's pose beside its descriptor on the wire (7 x f32).
inline constexpr std::size_t kKeyframePoseBytes = 28;
/// Keyframe candidates: tighter than the rooms' SC_th (0.35), there are many more of them.
inline constexpr float kKeyframeScThreshold = 0.25f;

/// Sends `from`'s keyframes not sent yet to every other robot.
void ExchangeKeyframes(Mission& mission, Robot& from);
/// Matches what `a` received against its own keyframes; re-solves a's graph when it changed.
void MatchKeyframes(Mission& mission, Robot& a);

}  // namespace msgraphs::tools::collab
