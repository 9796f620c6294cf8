// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/velodyne/sensor_model.hpp"

#include <algorithm>
#include <numbers>

namespace msgraphs::drivers::velodyne {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

void AssignRings(ModelInfo& info) {
  std::array<int, 32> order{};
  for (int i = 0; i < info.lasers; ++i) order[static_cast<std::size_t>(i)] = i;
  std::sort(order.begin(), order.begin() + info.lasers, [&](int a, int b) {
    return info.laser[static_cast<std::size_t>(a)].elevation_rad <
           info.laser[static_cast<std::size_t>(b)].elevation_rad;
  });
  for (int r = 0; r < info.lasers; ++r) {
    info.laser[static_cast<std::size_t>(order[static_cast<std::size_t>(r)])].ring =
        static_cast<std::uint8_t>(r);
  }
}

ModelInfo MakeVlp16() {
  ModelInfo info{SensorModel::kVlp16, 16, 2, 2 * kVlp16SequenceNs, {}};
  // Elevations alternate -15, +1, -13, +3, ... (degrees); offsets from the manual, in mm.
  constexpr std::array<double, 16> kOffsetMm = {11.2, -0.7, 9.7,  -2.2, 8.1,  -3.7, 6.6,  -5.1,
                                                5.1,  -6.6, 3.7,  -8.1, 2.2,  -9.7, 0.7,  -11.2};
  for (int i = 0; i < 16; ++i) {
    const double elevation_deg = (i % 2 == 0) ? -15.0 + i : 1.0 + (i - 1);
    auto& laser = info.laser[static_cast<std::size_t>(i)];
    laser.elevation_rad = elevation_deg * kDegToRad;
    laser.vertical_offset_m = kOffsetMm[static_cast<std::size_t>(i)] * 1e-3;
  }
  AssignRings(info);
  return info;
}

ModelInfo MakeHdl32e() {
  ModelInfo info{SensorModel::kHdl32e, 32, 1, kHdl32eBlockNs, {}};
  // Even ids from -30.67 deg, odd ids from -9.33 deg, both in steps of 4/3 deg (the ROS
  // driver's 32db.yaml has the same values in radians).
  for (int i = 0; i < 32; ++i) {
    const int k = i / 2;
    const double elevation_deg =
        (i % 2 == 0) ? -92.0 / 3.0 + 4.0 / 3.0 * k : -28.0 / 3.0 + 4.0 / 3.0 * k;
    info.laser[static_cast<std::size_t>(i)].elevation_rad = elevation_deg * kDegToRad;
  }
  AssignRings(info);
  return info;
}

}  // namespace

std::uint32_t ModelInfo::ChannelTimeNs(int block, int channel) const {
  const auto b = static_cast<std::uint32_t>(block);
  const auto c = static_cast<std::uint32_t>(channel);
  if (model == SensorModel::kVlp16) {
    return b * block_duration_ns + (c / 16u) * kVlp16SequenceNs + (c % 16u) * kVlp16LaserSpacingNs;
  }
  return b * block_duration_ns + (c / 2u) * kHdl32ePairSpacingNs;
}

const ModelInfo& GetModelInfo(SensorModel model) {
  static const ModelInfo kVlp16 = MakeVlp16();
  static const ModelInfo kHdl32e = MakeHdl32e();
  return model == SensorModel::kVlp16 ? kVlp16 : kHdl32e;
}

bool ModelFromPacketSpacing(std::uint32_t spacing_us, ReturnMode mode, SensorModel& model) {
  for (SensorModel candidate : {SensorModel::kVlp16, SensorModel::kHdl32e}) {
    const double expected_us = GetModelInfo(candidate).PacketDurationNs(mode) * 1e-3;
    const double error = static_cast<double>(spacing_us) - expected_us;
    if (error < 0.03 * expected_us && -error < 0.03 * expected_us) {
      model = candidate;
      return true;
    }
  }
  return false;
}

const char* ToString(SensorModel model) noexcept {
  return model == SensorModel::kVlp16 ? "VLP-16" : "HDL-32E";
}

}  // namespace msgraphs::drivers::velodyne
