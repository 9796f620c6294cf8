// SPDX-License-Identifier: MIT
// Frames in, poses out: decoding, pairing and integration of the encoder odometry with one set
// of counters, whatever the frames' source (SocketCAN, a candump log, a simulator). CRC failures,
// bad lengths, unknown ids and error frames are counted and skipped, never fatal (spec section 3).
#pragma once

#include <cstdint>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/drivers/can_odometry/can_frame.hpp"
#include "msgraphs/drivers/can_odometry/odometry_integrator.hpp"
#include "msgraphs/drivers/can_odometry/sample_assembler.hpp"

namespace msgraphs::drivers::can_odometry {

struct OdometryStreamStats {
  std::uint64_t frames = 0;
  std::uint64_t foreign_ids = 0;   ///< ids the DBC does not define (and extended/remote frames)
  std::uint64_t crc_errors = 0;
  std::uint64_t bad_frames = 0;    ///< wrong length, error frames
  std::uint64_t rejected_samples = 0;  ///< duplicates and out-of-order samples
  SampleAssemblerStats pairing;
  OdometryIntegratorStats integration;
};

class OdometryStream {
 public:
  static Expected<OdometryStream> Create(const OdometryIntegratorConfig& config);

  /// Feeds one frame received at `receive_time`. Returns true when it completed a sample that
  /// was integrated; the pose is then in pose().
  bool Add(const CanFrame& frame, UnixTime receive_time);

  const OdometryPose& pose() const { return pose_; }
  OdometryStreamStats stats() const;

 private:
  explicit OdometryStream(OdometryIntegrator integrator) : integrator_(std::move(integrator)) {}
  SampleAssembler assembler_;
  OdometryIntegrator integrator_;
  OdometryPose pose_;
  OdometryStreamStats stats_;
};

}  // namespace msgraphs::drivers::can_odometry
