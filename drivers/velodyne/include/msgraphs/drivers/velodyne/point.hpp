// SPDX-License-Identifier: MIT
// One decoded Velodyne return, in the lidar frame of ../shared/spec/README.md (the ROS
// velodyne_pointcloud convention: x towards azimuth 0, y left, z up).
#pragma once

#include <cstdint>

namespace msgraphs::drivers::velodyne {

/// Which return a point is. In dual mode the sensor sends the last return and, in the paired
/// block, the strongest one (or the second strongest when the strongest is also the last).
enum class ReturnTag : std::uint8_t {
  kStrongest = 0,      ///< single-return packet, mode 0x37
  kLast = 1,           ///< single-return packet, mode 0x38
  kDualLast = 2,       ///< dual packet, even block
  kDualStrongest = 3,  ///< dual packet, odd block (strongest or second strongest)
};

struct VelodynePoint {
  float x_m = 0.0f;
  float y_m = 0.0f;
  float z_m = 0.0f;
  float range_m = 0.0f;
  /// Firing time relative to the packet's first firing (the device timestamp), nanoseconds.
  std::uint32_t time_offset_ns = 0;
  /// Azimuth interpolated to this firing, 0.01 degree units, 0..35999, clockwise seen from
  /// above (the sensor's own convention).
  std::uint16_t azimuth_cdeg = 0;
  std::uint8_t intensity = 0;  ///< calibrated reflectivity 0..255
  std::uint8_t laser_id = 0;
  std::uint8_t ring = 0;  ///< 0 = lowest beam
  ReturnTag return_tag = ReturnTag::kStrongest;
};
static_assert(sizeof(VelodynePoint) == 28, "keep the point compact: 28 bytes");

}  // namespace msgraphs::drivers::velodyne
