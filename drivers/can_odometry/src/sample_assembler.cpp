// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/can_odometry/sample_assembler.hpp"

namespace msgraphs::drivers::can_odometry {

void SampleAssembler::Store(Slot& slot, const OdomFrame& frame) {
  if (slot.filled) {
    if (slot.frame.sequence == frame.sequence) {
      ++stats_.stray_frames;  // a duplicate: keep the first copy
      return;
    }
    // The pending frame's sample was never closed by its 0x122: it is lost.
    ++stats_.incomplete_samples;
    // Its partner (if any) belongs to the same lost sample: drop it too, counted once above.
    Slot& other = (&slot == &planar_) ? spatial_ : planar_;
    if (other.filled && other.frame.sequence == slot.frame.sequence) other.filled = false;
  }
  slot.filled = true;
  slot.frame = frame;
}

bool SampleAssembler::Add(const OdomFrame& frame, UnixTime receive_time) {
  ++stats_.frames;
  switch (frame.kind) {
    case OdomFrameKind::kPlanar:
      Store(planar_, frame);
      return false;
    case OdomFrameKind::kSpatial:
      Store(spatial_, frame);
      return false;
    case OdomFrameKind::kSampleTime:
      break;
  }
  const bool have_planar = planar_.filled && planar_.frame.sequence == frame.sequence;
  const bool have_spatial = spatial_.filled && spatial_.frame.sequence == frame.sequence;
  if (!have_planar || !have_spatial) {
    ++stats_.incomplete_samples;
    if (have_planar) planar_.filled = false;
    if (have_spatial) spatial_.filled = false;
    return false;
  }
  planar_.filled = false;
  spatial_.filled = false;
  OdomSampleValues& v = sample_.values;
  v.sequence = frame.sequence;
  v.sample_time_us = frame.sample_time_us;
  v.status = frame.status;
  v.dx_m = planar_.frame.a * kTranslationUnitM;
  v.dy_m = planar_.frame.b * kTranslationUnitM;
  v.dyaw_rad = planar_.frame.c * kRotationUnitRad;
  v.dz_m = spatial_.frame.a * kTranslationUnitM;
  v.droll_rad = spatial_.frame.b * kRotationUnitRad;
  v.dpitch_rad = spatial_.frame.c * kRotationUnitRad;
  sample_.receive_time = receive_time;
  ++stats_.samples;
  return true;
}

}  // namespace msgraphs::drivers::can_odometry
