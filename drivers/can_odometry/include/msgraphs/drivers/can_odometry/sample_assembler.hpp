// SPDX-License-Identifier: MIT
// Pairs the three frames of a sample by their Sequence. 0x122 is sent last and closes the
// sample; a sample missing a frame is counted as incomplete and never delivered (its motion is
// then bridged by the integrator like any other missing sample).
#pragma once

#include <cstdint>

#include "msgraphs/base/time.hpp"
#include "msgraphs/drivers/can_odometry/odometry_frames.hpp"

namespace msgraphs::drivers::can_odometry {

struct OdomSample {
  OdomSampleValues values;  ///< physical units
  UnixTime receive_time;    ///< host time of the closing 0x122 frame
};

struct SampleAssemblerStats {
  std::uint64_t frames = 0;
  std::uint64_t samples = 0;
  std::uint64_t incomplete_samples = 0;  ///< a frame of the sample never arrived
  std::uint64_t stray_frames = 0;        ///< a repeated frame for a sequence already pending
};

class SampleAssembler {
 public:
  /// Returns true when `frame` completed a sample, which is then in sample().
  bool Add(const OdomFrame& frame, UnixTime receive_time);
  const OdomSample& sample() const { return sample_; }
  const SampleAssemblerStats& stats() const { return stats_; }

 private:
  struct Slot {
    bool filled = false;
    OdomFrame frame;
  };
  void Store(Slot& slot, const OdomFrame& frame);

  Slot planar_;
  Slot spatial_;
  OdomSample sample_;
  SampleAssemblerStats stats_;
};

}  // namespace msgraphs::drivers::can_odometry
