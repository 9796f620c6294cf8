// SPDX-License-Identifier: MIT
// The scan-matching fitness limit, from the robot's own matches.
//
// Fitness (mean squared nearest-neighbour distance within a cut-off) mixes two things: how well
// the scan fits the local map, and how much of it lies in space the map has not seen yet (a
// keyframe through a door, a turn into a hall). The second depends on the building and the
// sensor, not on the match: on the benchmark's buildings correct matches ran from 0.002 to
// 0.11 m^2 (median 0.024, p90 0.054) while matches 0.15-0.6 m wrong ran from 0.016 to 0.14, so
// no fixed limit separates them, and a fixed 0.05 refuses one correct match in eight, which
// after a foot slip leaves the step to the slipped odometry (docs/s-graph.md, "Fitness gate").
// The gate keeps the configured limit as its floor and widens it to the upper outlier bound of
// the fitnesses of the robot's own recent matches, median + z * 1.4826 * MAD (the modified
// z-score outlier rule of Iglewicz and Hoaglin, z = 3.5). The window holds matches
// refused by fitness too: a sensor whose every fitness is above the floor is still matched once
// min_samples are in. A match that fits far worse than this robot's matches in this building do
// is still refused. LocalMapper has it off by default: the matches it lets through above the
// floor are as often 6-20 cm off as right, and fitness cannot tell (docs/s-graph.md).
//
// Init allocates the window; Add and Limit allocate nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs {
class SnapshotReader;
class SnapshotWriter;
}  // namespace msgraphs

namespace msgraphs::core {

struct FitnessGateConfig {
  double floor_m2 = 0.05;       ///< the limit before the robot has its own figures, and its least
  std::size_t window = 100;     ///< the last this many matches (a few minutes of walking)
  std::size_t min_samples = 10; ///< fewer than this: the floor alone
  double outlier_z = 3.5;       ///< modified z-score beyond which a fitness is an outlier; 0: floor only
  Status Validate() const;
};

class FitnessGate {
 public:
  /// Its state in a snapshot (LocalMapper::Save / Load): the reader fails on a store of another
  /// size or a value out of range.
  void Save(SnapshotWriter& w) const;
  void Load(SnapshotReader& r);
  Status Init(const FitnessGateConfig& config);
  /// A judged match's fitness (non-finite or negative values are ignored and counted).
  void Add(double fitness_m2);
  /// The limit now: the floor, or the robot's own outlier bound where that is higher.
  [[nodiscard]] double Limit();
  [[nodiscard]] std::size_t samples() const { return count_; }
  [[nodiscard]] std::uint64_t ignored() const { return ignored_; }
  void Reset();

 private:
  template <class Archive>
  void Io(Archive& ar);
  FitnessGateConfig config_;
  std::vector<double> ring_, scratch_;
  std::size_t next_ = 0, count_ = 0;
  std::uint64_t ignored_ = 0;
};

}  // namespace msgraphs::core
