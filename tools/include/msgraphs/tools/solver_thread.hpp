// SPDX-License-Identifier: MIT
// Each full solve a LocalMapper begins, run on a thread of its own as the node's solver thread
// does, for the host tools that measure time (msgraphs_slam, msgraphs_collab --timing). The map
// does not depend on it: the mapper applies the solve at a fixed keyframe and runs it there
// itself if no thread has.
#pragma once

#include <cstdint>
#include <thread>

#include "msgraphs/core/slam/local_mapper.hpp"

namespace msgraphs::tools {

class SolverThread {
 public:
  /// After each AddScan: starts a thread for a full solve the mapper began since the last call.
  void Follow(core::LocalMapper& mapper);
  /// Waits for the last thread (before LocalMapper::Finish, or before the mapper goes).
  void Join();

 private:
  std::uint64_t solves_begun_ = 0;
  std::jthread thread_;
};

}  // namespace msgraphs::tools
