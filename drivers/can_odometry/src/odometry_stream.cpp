// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/can_odometry/odometry_stream.hpp"

#include "msgraphs/drivers/can_odometry/odometry_frames.hpp"

namespace msgraphs::drivers::can_odometry {

Expected<OdometryStream> OdometryStream::Create(const OdometryIntegratorConfig& config) {
  auto integrator = OdometryIntegrator::Create(config);
  if (!integrator) return integrator.error();
  return OdometryStream(std::move(integrator).value());
}

bool OdometryStream::Add(const CanFrame& frame, UnixTime receive_time) {
  ++stats_.frames;
  auto decoded = DecodeOdomFrame(frame);
  if (!decoded) {
    switch (decoded.error().code) {
      case Errc::kNotFound: ++stats_.foreign_ids; break;
      case Errc::kChecksum: ++stats_.crc_errors; break;
      default: ++stats_.bad_frames; break;
    }
    return false;
  }
  if (!assembler_.Add(*decoded, receive_time)) return false;
  auto pose = integrator_.Add(assembler_.sample());
  if (!pose) {
    ++stats_.rejected_samples;
    return false;
  }
  pose_ = *pose;
  return true;
}

OdometryStreamStats OdometryStream::stats() const {
  OdometryStreamStats s = stats_;
  s.pairing = assembler_.stats();
  s.integration = integrator_.stats();
  return s;
}

}  // namespace msgraphs::drivers::can_odometry
