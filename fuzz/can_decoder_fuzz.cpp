// SPDX-License-Identifier: MIT
// libFuzzer target: arbitrary bytes as a stream of CAN frames (id selector, 8 data bytes, a
// receive-time step) through decoding, sample pairing and integration. Invariants: no crash,
// the integrated pose stays finite with a unit quaternion.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "msgraphs/drivers/can_odometry/crc8.hpp"
#include "msgraphs/drivers/can_odometry/odometry_frames.hpp"
#include "msgraphs/drivers/can_odometry/odometry_integrator.hpp"
#include "msgraphs/drivers/can_odometry/sample_assembler.hpp"

using namespace msgraphs;
using namespace msgraphs::drivers::can_odometry;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  SampleAssembler assembler;
  auto integrator = OdometryIntegrator::Create({}).value();
  std::int64_t t_ns = 1'700'000'000'000'000'000;
  constexpr std::size_t kRecord = 11;
  for (std::size_t o = 0; o + kRecord <= size; o += kRecord) {
    const std::uint8_t* r = data + o;
    CanFrame f;
    f.id = 0x120u + (r[0] & 0x03u);  // mostly odometry ids, sometimes 0x123
    f.length = (r[0] & 0x80u) != 0 ? static_cast<std::uint8_t>(r[0] & 0x0Fu) % 9 : 8;
    std::memcpy(f.data.data(), r + 1, 8);
    if ((r[0] & 0x40u) == 0) f.data[7] = Crc8SaeJ1850({f.data.data(), 7});  // mostly valid CRCs
    t_ns += static_cast<std::int64_t>(r[9] | (r[10] << 8)) * 1000 - 10'000'000;
    auto d = DecodeOdomFrame(f);
    if (!d || !assembler.Add(*d, UnixTime::FromNanoseconds(t_ns))) continue;
    auto pose = integrator.Add(assembler.sample());
    if (!pose) continue;
    const Pose3& p = pose->T_odom_base;
    const double n = p.qw * p.qw + p.qx * p.qx + p.qy * p.qy + p.qz * p.qz;
    if (!std::isfinite(p.x_m) || !std::isfinite(p.y_m) || !std::isfinite(p.z_m) || std::fabs(n - 1.0) > 1e-6) {
      std::abort();
    }
  }
  return 0;
}
