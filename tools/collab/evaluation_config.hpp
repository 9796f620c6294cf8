// SPDX-License-Identifier: MIT
// What makes a view or a match "wrong" against the truth in msgraphs_collab's evaluation
// (evaluation.hpp): the view thresholds are options, the match thresholds constants.
#pragma once

namespace msgraphs::tools::collab {

struct EvaluationConfig {
  /// A merged view is wrong when its origin is further than this from the truth (3-D) ...
  double wrong_origin_m = 0.5;
  /// ... or turned by more than this. Both documented options (--wrong-origin-m/-deg).
  double wrong_origin_deg = 2.0;
};

/// An accepted match is wrong when its map-to-map transform is further than these from the
/// truth (horizontal translation, rotation angle): a room period off is metres.
inline constexpr double kWrongMatch_m = 0.5;
inline constexpr double kWrongMatch_rad = 0.1;

}  // namespace msgraphs::tools::collab
