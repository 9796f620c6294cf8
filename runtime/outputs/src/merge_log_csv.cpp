// SPDX-License-Identifier: MIT
#include "msgraphs/runtime/outputs/merge_log_csv.hpp"

#include <cmath>

namespace msgraphs::runtime::outputs {

void WriteMergeLogHeader(std::ostream& out, std::uint16_t robot, const char* time_what) {
  out << "# robot " << robot << "'s merge decisions (" << time_what
      << "): the peer, what changed, the rule's verdict, the leading transform (the peer's map in "
         "ours), its evidence in metres of wall (agreement, in its weakest direction, in conflict with "
         "free space), the strongest standing rival's; transforms set aside by place evidence and the place clouds weighed\n"
         "sequence,time_s,peer,event,verdict,x,y,z,yaw_rad,agreement_m,constraint_m,conflict_m,"
         "rival_agreement_m,rival_constraint_m,rival_conflict_m,rival_from_symmetry,symmetric,"
         "hypotheses,refuted,set_aside,places\n";
}

void WriteMergeLogRows(std::ostream& out, std::span<const core::MergeLogEntry> entries) {
  for (const core::MergeLogEntry& e : entries) {
    const Eigen::Vector3d& t = e.T_self_peer.translation();
    const Eigen::Vector3d x = e.T_self_peer.linear().col(0);
    out << e.sequence << ',' << e.now_s << ',' << e.peer << ',' << core::ToString(e.event) << ",\""
        << core::ToString(e.verdict) << "\"," << t.x() << ',' << t.y() << ',' << t.z() << ','
        << std::atan2(x.y(), x.x()) << ',' << e.leader.agreement_m << ',' << e.leader.constraint_m << ','
        << e.leader.conflict_m << ',' << e.rival.agreement_m << ',' << e.rival.constraint_m << ','
        << e.rival.conflict_m << ',' << (e.rival_from_symmetry ? 1 : 0) << ',' << (e.symmetric ? 1 : 0) << ','
        << e.hypotheses << ',' << e.refuted << ',' << e.set_aside << ',' << e.places << '\n';
  }
}

}  // namespace msgraphs::runtime::outputs
