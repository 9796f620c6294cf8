// SPDX-License-Identifier: MIT
// msgraphs_odometry_tum: encoder odometry from a candump log as a TUM trajectory of the base
// frame (the encoder-only baseline the SLAM estimates are compared with). Prints what the
// decoder counted.
//
//   msgraphs_odometry_tum --candump odometry.log --out odometry.tum
#include <cstdio>
#include <string>

#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/can_odometry/odometry_stream.hpp"

int main(int argc, char** argv) {
  namespace can = msgraphs::drivers::can_odometry;
  std::string in, out;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--candump") in = argv[i + 1];
    else if (a == "--out") out = argv[i + 1];
  }
  if (in.empty() || out.empty()) {
    std::fprintf(stderr, "usage: msgraphs_odometry_tum --candump LOG --out FILE.tum\n");
    return 2;
  }
  auto reader = can::CandumpFileReader::Open(in.c_str());
  if (!reader) {
    std::fprintf(stderr, "odometry_tum: %s: %s\n", in.c_str(), reader.error().detail);
    return 1;
  }
  auto stream = can::OdometryStream::Create({}).value();
  std::FILE* f = std::fopen(out.c_str(), "w");
  if (f == nullptr) return 1;
  can::CandumpLine line;
  std::size_t poses = 0;
  while (reader->Next(line).value_or(false)) {
    if (!stream.Add(line.frame, line.stamp)) continue;
    const auto& p = stream.pose();
    const auto& T = p.T_odom_base;
    std::fprintf(f, "%.6f %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n", p.stamp.seconds_since_epoch(), T.x_m, T.y_m, T.z_m,
                 T.qx, T.qy, T.qz, T.qw);
    ++poses;
  }
  std::fclose(f);
  const auto s = stream.stats();
  std::printf("odometry: %zu poses; %llu gaps (%llu samples bridged), %llu CRC errors, %llu foreign frames\n", poses,
              static_cast<unsigned long long>(s.integration.gaps), static_cast<unsigned long long>(s.integration.missing_samples),
              static_cast<unsigned long long>(s.crc_errors), static_cast<unsigned long long>(s.foreign_ids));
  return 0;
}
