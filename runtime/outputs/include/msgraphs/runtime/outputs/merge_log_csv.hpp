// SPDX-License-Identifier: MIT
// merge_log.csv: every merge decision a robot's session logged (core::MergeLogEntry), one line
// each, with its evidence and its strongest rival (docs/multi-robot.md, "The merge rule"). The
// node writes it at exit; msgraphs_collab --out writes one per robot.
#pragma once

#include <ostream>
#include <span>

#include "msgraphs/core/collab/collab_session.hpp"

namespace msgraphs::runtime::outputs {

/// The header (two comment lines naming the columns), for robot `robot`; `time_what` says what
/// the time column counts ("seconds since the node started", "mission time").
void WriteMergeLogHeader(std::ostream& out, std::uint16_t robot, const char* time_what);
void WriteMergeLogRows(std::ostream& out, std::span<const core::MergeLogEntry> entries);

}  // namespace msgraphs::runtime::outputs
