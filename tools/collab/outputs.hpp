// SPDX-License-Identifier: MIT
// msgraphs_collab's --out DIR files:
//   robotB_in_robotA.tum  for every viewer A and every robot B it merged (and robotA_in_robotA):
//                         B's keyframes in A's map frame through A's estimate of B's origin
//                         (TUM: B's recording clock, metres, Hamilton quaternion);
//   bytes.csv             cumulative bytes per message type after each exchange (the last row
//                         is the final exchange: the mission's totals);
//   merge_log_robotN.csv  every merge decision robot N's session logged, with its evidence and
//                         its strongest rival (the node's merge_log.csv; time: mission time).
#pragma once

#include <string>

#include "evaluation.hpp"
#include "lockstep_runner.hpp"
#include "mission.hpp"

namespace msgraphs::tools::collab {

/// False with `error` naming the file that could not be written.
bool WriteOutputs(const std::string& out_dir,
                  const Mission& mission,
                  const Evaluation& evaluation,
                  const MissionRun& run,
                  std::string& error);

}  // namespace msgraphs::tools::collab
