// SPDX-License-Identifier: MIT
// The symmetric variants the summary reports are checked, not assumed: a room is listed as an
// identical copy (or a mirror image) only when its outline, its doors and its furniture are
// the original's mapped by the translation (or the reflection), to a micrometre.
#pragma once

#include <vector>

#include "doors.hpp"
#include "room_layout.hpp"

namespace msgraphs::sim::building {

/// Keeps in plan.identical_groups and plan.mirror_pairs only the rooms that really are copies.
void KeepVerifiedCopies(Plan& plan,
                        const std::vector<PlacedDoor>& doors,
                        const std::vector<std::vector<Item>>& items);

}  // namespace msgraphs::sim::building
