// SPDX-License-Identifier: MIT
// An msgraphs_collab mission: every robot, the radio between them, and one exchange: each
// robot's CollabSession publishes what changed, the messages cross the radio (really encoded and
// decoded), every session matches twice so that cloud requests and answers complete, and each
// mapper takes its session's wall priors (feedback). The keyframe-level baseline
// (keyframe_baseline.hpp) replaces the session's part when `keyframes` is set.
//
// The view accessors (Merged, Origin, Accepted, Factors) are the only place the evaluation reads
// a robot's estimate of another, through CollabSession's public API or the baseline's graph.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <vector>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/core/collab/collab_session.hpp"
#include "msgraphs/core/collab/room_matcher.hpp"
#include "msgraphs/core/collab/room_messages.hpp"
#include "radio.hpp"
#include "robot.hpp"

namespace msgraphs::tools::collab {

struct Mission {
  std::vector<std::unique_ptr<Robot>> robots;
  bool keyframes = false;  ///< the baseline instead of the room-based algorithm
  bool feedback = true;    ///< other robots' walls back into each local S-Graph
  std::vector<core::PlanePrior> priors = std::vector<core::PlanePrior>(512);
  core::CloudEncoding cloud_encoding = core::CloudEncoding::kQuantised16;
  core::RoomMatcher matcher;  ///< the baseline's
  Accounting accounting;
  Radio radio;
  std::vector<std::uint8_t> buffer = std::vector<std::uint8_t>(8 << 20);
  BoundedVector<Eigen::Vector3f> decoded_cloud{200000};

  /// One exchange between every robot (see the file comment), at mission time `now_s` (it stamps
  /// the merge decisions).
  void Exchange(double now_s);
  /// Hands every queued message to its addressees, counting bytes and refusals.
  void Deliver();

  // ---- robot a's view of robot b (by 0-based index) ----
  bool Merged(const Robot& a, int b_index) const;
  /// Robot b's map frame in robot a's (meaningful when Merged).
  Eigen::Isometry3d Origin(const Robot& a, int b_index) const;
  /// The accepted (consistent) room or keyframe matches of a with b.
  std::vector<core::RoomMatch> Accepted(const Robot& a, int b_index) const;
  /// Factors of robot b in a's collaborative graph.
  std::size_t Factors(const Robot& a, int b_index) const;
};

}  // namespace msgraphs::tools::collab
