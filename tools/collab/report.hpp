// SPDX-License-Identifier: MIT
// msgraphs_collab's reports of one mission: the text report (stdout), its one-row markdown
// form (--markdown), and the machine-readable summary (--summary FILE, JSON; the schema is in
// docs/collab-summary.md). The JSON holds every figure the text prints.
#pragma once

#include <string>

#include "evaluation.hpp"
#include "explain.hpp"
#include "lockstep_runner.hpp"
#include "mission.hpp"
#include "options.hpp"

namespace msgraphs::tools::collab {

struct ReportInput {
  const Options& options;
  const Mission& mission;
  const MissionRun& run;
  const Evaluation& evaluation;
  const std::vector<ViewExplanation>& explanations;  ///< per view (room-based modes)
};

/// The text report.
std::string TextReport(const ReportInput& in);
/// `| run | robots | mode | merged | ATE | MB | matches right / accepted | wrong |` of robot 1's
/// view.
std::string MarkdownRow(const ReportInput& in);
/// The JSON summary (schema version kSummaryVersion).
std::string JsonSummary(const ReportInput& in);

inline constexpr int kSummaryVersion = 1;

}  // namespace msgraphs::tools::collab
