// SPDX-License-Identifier: MIT
// Every figure msgraphs_collab prints from CollabPeerStats and CollabSessionStats, as text and
// as JSON, in one place: those structs follow the merge decision inside core/collab, which is
// being redesigned, and only this file has to follow them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "json_writer.hpp"
#include "msgraphs/core/collab/collab_session.hpp"

namespace msgraphs::tools::collab {

/// Robot `robot` among `session`'s peers, or nullopt when it never heard from it.
std::optional<core::CollabPeerStats> FindPeerStats(const core::CollabSession& session,
                                                   std::uint16_t robot);

/// "  view of robot 1: robot 2 merged, 4 hypotheses (...); 0 accepted matches wrong", or ""
/// when there is nothing to say (one hypothesis, merged, no wrong match).
std::string PeerStatsLine(int viewer, const core::CollabPeerStats& p, std::size_t wrong);

/// "robot 1 session: 7 own rooms (...)".
std::string SessionStatsLine(int robot, const core::CollabSessionStats& st);

void WritePeerStats(JsonWriter& json, const core::CollabPeerStats& p);
void WriteSessionStats(JsonWriter& json, const core::CollabSessionStats& st);

}  // namespace msgraphs::tools::collab
