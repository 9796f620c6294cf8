// SPDX-License-Identifier: MIT
// CAN encoder odometry: frame decoding and CRC, sample pairing, integration into SE(3) with
// gaps, wraps, invalid and out-of-order samples, candump lines, zero allocation per frame.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "msgraphs/drivers/can_odometry/candump.hpp"
#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/can_odometry/crc8.hpp"
#include "msgraphs/drivers/can_odometry/odometry_frames.hpp"
#include "msgraphs/drivers/can_odometry/odometry_integrator.hpp"
#include "msgraphs/drivers/can_odometry/odometry_stream.hpp"
#include "msgraphs/drivers/can_odometry/sample_assembler.hpp"
#include "test_data.hpp"

namespace msgraphs::drivers::can_odometry {
namespace {

// ---- frames ------------------------------------------------------------------------------------

TEST(OdomFrames, EncodeDecodeRoundTripWithinQuantisation) {
  OdomSampleValues v;
  v.sequence = 200;
  v.sample_time_us = 0xDEADBEEF;
  v.status = kStatusValid | kStatusSlipSuspected;
  v.dx_m = 0.02034;
  v.dy_m = -0.0011;
  v.dz_m = 0.0003;
  v.droll_rad = -0.00012;
  v.dpitch_rad = 0.00031;
  v.dyaw_rad = 0.0123;
  const auto frames = EncodeOdomSample(v);
  EXPECT_EQ(frames[0].id, kPlanarId);
  EXPECT_EQ(frames[1].id, kSpatialId);
  EXPECT_EQ(frames[2].id, kSampleTimeId);
  SampleAssembler assembler;
  const UnixTime t = UnixTime::FromSeconds(1700000000.0);
  EXPECT_FALSE(assembler.Add(DecodeOdomFrame(frames[0]).value(), t));
  EXPECT_FALSE(assembler.Add(DecodeOdomFrame(frames[1]).value(), t));
  ASSERT_TRUE(assembler.Add(DecodeOdomFrame(frames[2]).value(), t));
  const OdomSampleValues& got = assembler.sample().values;
  EXPECT_EQ(got.sequence, 200);
  EXPECT_EQ(got.sample_time_us, 0xDEADBEEFu);
  EXPECT_EQ(got.status, 3);
  EXPECT_NEAR(got.dx_m, 0.0203, 1e-9);  // 0.1 mm steps
  EXPECT_NEAR(got.dy_m, -0.0011, 1e-9);
  EXPECT_NEAR(got.dz_m, 0.0003, 1e-9);
  EXPECT_NEAR(got.droll_rad, -0.00012, 1e-9);
  EXPECT_NEAR(got.dpitch_rad, 0.00031, 1e-9);
  EXPECT_NEAR(got.dyaw_rad, 0.0123, 1e-9);
}

TEST(OdomFrames, KnownBytesDecodeAsTheDbcSays) {
  // DeltaX = 0x0102 = 258 -> 0.0258 m, DeltaY = -2 -> -0.0002 m, DeltaYaw = 0x7FFF -> 0.32767 rad.
  CanFrame f;
  f.id = kPlanarId;
  f.length = 8;
  f.data = {0x02, 0x01, 0xFE, 0xFF, 0xFF, 0x7F, 0x09, 0x00};
  std::uint8_t crc_input[7] = {0x02, 0x01, 0xFE, 0xFF, 0xFF, 0x7F, 0x09};
  f.data[7] = Crc8SaeJ1850(crc_input);
  auto d = DecodeOdomFrame(f).value();
  EXPECT_EQ(d.kind, OdomFrameKind::kPlanar);
  EXPECT_EQ(d.a, 258);
  EXPECT_EQ(d.b, -2);
  EXPECT_EQ(d.c, 32767);
  EXPECT_EQ(d.sequence, 9);
}

TEST(OdomFrames, BadFramesAreClassified) {
  auto good = EncodeOdomSample({})[0];
  CanFrame crc = good;
  crc.data[2] ^= 0x10;
  EXPECT_EQ(DecodeOdomFrame(crc).error().code, Errc::kChecksum);
  CanFrame short_frame = good;
  short_frame.length = 7;
  EXPECT_EQ(DecodeOdomFrame(short_frame).error().code, Errc::kMalformed);
  CanFrame unknown = good;
  unknown.id = 0x123;
  EXPECT_EQ(DecodeOdomFrame(unknown).error().code, Errc::kNotFound);
  CanFrame extended = good;
  extended.extended = true;
  EXPECT_EQ(DecodeOdomFrame(extended).error().code, Errc::kNotFound);
  CanFrame error = good;
  error.error = true;
  EXPECT_EQ(DecodeOdomFrame(error).error().code, Errc::kMalformed);
  OdomSampleValues huge;
  huge.dx_m = 10.0;  // beyond +-3.2767 m: saturates, never wraps sign
  huge.dyaw_rad = std::nan("");
  auto frames = EncodeOdomSample(huge);
  EXPECT_EQ(DecodeOdomFrame(frames[0]).value().a, 32767);
  EXPECT_EQ(DecodeOdomFrame(frames[0]).value().c, -32768);
}

// ---- pairing -----------------------------------------------------------------------------------

TEST(SampleAssembler, MissingFramesMakeIncompleteSamplesCountedOnce) {
  SampleAssembler a;
  const UnixTime t;
  auto add_sample = [&](std::uint8_t seq, bool planar, bool spatial, bool timing) {
    OdomSampleValues v;
    v.sequence = seq;
    v.sample_time_us = seq * 20000u;
    const auto f = EncodeOdomSample(v);
    bool done = false;
    if (planar) done |= a.Add(DecodeOdomFrame(f[0]).value(), t);
    if (spatial) done |= a.Add(DecodeOdomFrame(f[1]).value(), t);
    if (timing) done |= a.Add(DecodeOdomFrame(f[2]).value(), t);
    return done;
  };
  EXPECT_TRUE(add_sample(1, true, true, true));
  EXPECT_FALSE(add_sample(2, true, false, true));   // spatial lost
  EXPECT_FALSE(add_sample(3, true, true, false));   // closing frame lost
  EXPECT_TRUE(add_sample(4, true, true, true));     // sample 3's pending frames are dropped
  EXPECT_FALSE(add_sample(5, false, true, false));  // only spatial
  EXPECT_TRUE(add_sample(6, true, true, true));
  EXPECT_EQ(a.stats().samples, 3u);
  EXPECT_EQ(a.stats().incomplete_samples, 3u);
  // A duplicated frame is ignored, not a second sample.
  OdomSampleValues v;
  v.sequence = 7;
  const auto f = EncodeOdomSample(v);
  EXPECT_FALSE(a.Add(DecodeOdomFrame(f[0]).value(), t));
  EXPECT_FALSE(a.Add(DecodeOdomFrame(f[0]).value(), t));
  EXPECT_FALSE(a.Add(DecodeOdomFrame(f[1]).value(), t));
  EXPECT_TRUE(a.Add(DecodeOdomFrame(f[2]).value(), t));
  EXPECT_EQ(a.stats().stray_frames, 1u);
}

// ---- integration -------------------------------------------------------------------------------

struct Simulated {
  // A robot moving at v m/s and w rad/s, sampled at 50 Hz with the DBC's quantisation.
  double v = 1.0, w = 0.0;
  std::uint32_t time_us = 4'290'000'000u;  // the 32-bit microsecond clock wraps after 248 samples
  std::uint8_t sequence = 250;
  UnixTime host = UnixTime::FromSeconds(1700000000.0);

  OdomSample Next(std::uint8_t status = kStatusValid) {
    OdomSample s;
    s.values.sequence = sequence++;
    time_us += 20000;
    s.values.sample_time_us = time_us;
    s.values.status = status;
    // Exact arc over 20 ms expressed in the previous body frame.
    const double dt = 0.02, dyaw = w * dt;
    const double chord = std::fabs(w) > 1e-12 ? 2.0 * v / w * std::sin(dyaw / 2) : v * dt;
    s.values.dx_m = std::round(chord * std::cos(dyaw / 2) * 1e4) / 1e4;
    s.values.dy_m = std::round(chord * std::sin(dyaw / 2) * 1e4) / 1e4;
    s.values.dyaw_rad = std::round(dyaw * 1e5) / 1e5;
    host += Duration::FromMicroseconds(20000);
    s.receive_time = host + Duration::FromMicroseconds(300);
    return s;
  }
};

double Yaw(const Pose3& p) {
  return std::atan2(2.0 * (p.qw * p.qz + p.qx * p.qy), 1.0 - 2.0 * (p.qy * p.qy + p.qz * p.qz));
}

TEST(OdometryIntegrator, StraightLineAcrossBothCounterWraps) {
  auto integrator = OdometryIntegrator::Create({}).value();
  Simulated sim;
  OdometryPose pose;
  for (int i = 0; i < 500; ++i) pose = integrator.Add(sim.Next()).value();  // 10 s
  EXPECT_NEAR(pose.T_odom_base.x_m, 499 * 0.02, 1e-6);
  EXPECT_NEAR(pose.T_odom_base.y_m, 0.0, 1e-9);
  EXPECT_EQ(integrator.stats().gaps, 0u);
  EXPECT_EQ(integrator.stats().samples, 500u);
  EXPECT_EQ(pose.flags, 0);
}

TEST(OdometryIntegrator, CircleClosesAndTimestampsFollowTheBridgeClock) {
  auto integrator = OdometryIntegrator::Create({}).value();
  Simulated sim;
  sim.v = 0.5;
  sim.w = 2 * std::numbers::pi / 10.0;  // one turn in 10 s, radius 0.796 m
  std::vector<OdometryPose> poses;
  for (int i = 0; i <= 500; ++i) poses.push_back(integrator.Add(sim.Next()).value());
  // After 500 steps (10 s) the robot is back where the first sample left it, up to the DBC's
  // quantisation (1e-5 rad and 0.1 mm per sample, accumulated over 500 samples).
  EXPECT_NEAR(poses.back().T_odom_base.x_m, 0.0, 5e-3);
  EXPECT_NEAR(poses.back().T_odom_base.y_m, 0.0, 5e-3);
  EXPECT_NEAR(std::remainder(Yaw(poses.back().T_odom_base), 2 * std::numbers::pi), 0.0, 2.5e-3);
  // Quarter turn: at (r, r) with yaw 90 degrees.
  const double r = 0.5 / sim.w;
  EXPECT_NEAR(poses[125].T_odom_base.x_m, r, 5e-3);
  EXPECT_NEAR(poses[125].T_odom_base.y_m, r, 5e-3);
  EXPECT_NEAR(Yaw(poses[125].T_odom_base), std::numbers::pi / 2, 1e-3);
  // Host stamps keep the bridge's exact 20 ms spacing.
  for (std::size_t i = 1; i < poses.size(); ++i) {
    EXPECT_EQ((poses[i].stamp - poses[i - 1].stamp).nanoseconds(), 20'000'000) << i;
  }
}

TEST(OdometryIntegrator, GapsAreBridgedCountedAndFlagged) {
  auto with_gap = OdometryIntegrator::Create({}).value();
  auto reference = OdometryIntegrator::Create({}).value();
  Simulated a, b;
  a.w = b.w = 0.3;
  OdometryPose pa, pb;
  for (int i = 0; i < 400; ++i) {
    const OdomSample s = a.Next();
    pb = reference.Add(b.Next()).value();
    if (i >= 100 && i < 110) continue;  // ten samples (200 ms) lost on the bus
    pa = with_gap.Add(s).value();
    if (i == 110) {
      EXPECT_TRUE(pa.flags & kPoseBridged);
      EXPECT_NEAR(pa.step_duration_s, 0.22, 1e-9);
    }
  }
  EXPECT_EQ(with_gap.stats().gaps, 1u);
  EXPECT_EQ(with_gap.stats().missing_samples, 10u);
  EXPECT_NEAR(with_gap.stats().bridged_seconds, 0.2, 1e-9);
  // Constant motion: the bridge recovers the lost 20 cm along the arc (to 1 mm after 8 m).
  EXPECT_NEAR(pa.T_odom_base.x_m, pb.T_odom_base.x_m, 1e-3);
  EXPECT_NEAR(pa.T_odom_base.y_m, pb.T_odom_base.y_m, 1e-3);
}

TEST(OdometryIntegrator, AGapLongerThanTheBridgeLimitIsADiscontinuity) {
  auto integrator = OdometryIntegrator::Create({}).value();
  Simulated sim;
  for (int i = 0; i < 10; ++i) static_cast<void>(integrator.Add(sim.Next()));
  for (int i = 0; i < 100; ++i) static_cast<void>(sim.Next());  // 2 s lost
  const OdometryPose pose = integrator.Add(sim.Next()).value();
  EXPECT_TRUE(pose.flags & kPoseDiscontinuity);
  EXPECT_EQ(integrator.stats().discontinuities, 1u);
  EXPECT_EQ(integrator.stats().missing_samples, 100u);
}

TEST(OdometryIntegrator, AGapBeyondTheSequenceRangeIsMeasuredByTime) {
  OdometryIntegratorConfig config;
  config.max_bridge = Duration::FromSeconds(10.0);
  auto integrator = OdometryIntegrator::Create(config).value();
  Simulated sim;
  for (int i = 0; i < 10; ++i) static_cast<void>(integrator.Add(sim.Next()));
  for (int i = 0; i < 300; ++i) static_cast<void>(sim.Next());  // 300 > 255 samples lost
  const OdometryPose pose = integrator.Add(sim.Next()).value();
  EXPECT_EQ(integrator.stats().missing_samples, 300u);
  EXPECT_NEAR(pose.T_odom_base.x_m, 10 * 0.02 + 0.02 * 300, 1e-3);
}

TEST(OdometryIntegrator, InvalidSamplesAreBridgedAndSlipIsFlagged) {
  auto integrator = OdometryIntegrator::Create({}).value();
  Simulated sim;
  for (int i = 0; i < 10; ++i) static_cast<void>(integrator.Add(sim.Next()));
  OdomSample bad = sim.Next(0);  // status: not valid
  bad.values.dx_m = 3.0;         // garbage that must not be integrated
  const OdometryPose p1 = integrator.Add(bad).value();
  EXPECT_TRUE(p1.flags & kPoseInvalidSample);
  EXPECT_NEAR(p1.T_odom_base.x_m, 10 * 0.02, 1e-6);  // bridged at the last speed
  const OdometryPose p2 = integrator.Add(sim.Next(kStatusValid | kStatusSlipSuspected)).value();
  EXPECT_TRUE(p2.flags & kPoseSlipSuspected);
  EXPECT_EQ(integrator.stats().invalid_samples, 1u);
  EXPECT_EQ(integrator.stats().slip_samples, 1u);
}

TEST(OdometryIntegrator, DuplicatesAndOldSamplesAreRejected) {
  auto integrator = OdometryIntegrator::Create({}).value();
  Simulated sim;
  const OdomSample first = sim.Next();
  static_cast<void>(integrator.Add(first));
  const OdomSample second = sim.Next();
  const OdometryPose before = integrator.Add(second).value();
  EXPECT_EQ(integrator.Add(second).error().code, Errc::kOutOfOrder);
  EXPECT_EQ(integrator.Add(first).error().code, Errc::kOutOfOrder);
  EXPECT_EQ(integrator.stats().duplicates, 1u);
  EXPECT_EQ(integrator.stats().out_of_order, 1u);
  const OdometryPose after = integrator.Add(sim.Next()).value();
  EXPECT_NEAR(after.T_odom_base.x_m - before.T_odom_base.x_m, 0.02, 1e-9);
}

TEST(OdometryIntegrator, RotationOrderIsYawPitchRoll) {
  // R = Rz(yaw) Ry(pitch) Rx(roll): rotate the x axis and compare with the matrix product.
  const double roll = 0.2, pitch = -0.3, yaw = 0.7;
  const Pose3 q = PoseFromDelta(0, 0, 0, roll, pitch, yaw);
  Pose3 unit_x;
  unit_x.x_m = 1.0;
  const Pose3 rotated = Compose(q, unit_x);
  // Rz Ry Rx applied to (1,0,0): Rx leaves it, Ry gives (cp, 0, -sp), Rz rotates about z.
  const double cp = std::cos(pitch), sp = std::sin(pitch);
  EXPECT_NEAR(rotated.x_m, std::cos(yaw) * cp, 1e-12);
  EXPECT_NEAR(rotated.y_m, std::sin(yaw) * cp, 1e-12);
  EXPECT_NEAR(rotated.z_m, -sp, 1e-12);
  Pose3 unit_y;
  unit_y.y_m = 1.0;
  const Pose3 ry = Compose(q, unit_y);
  // Rx(roll) (0,1,0) = (0, cr, sr); Ry: (sp sr, cr, cp sr); Rz rotates x,y.
  const double cr = std::cos(roll), sr = std::sin(roll);
  EXPECT_NEAR(ry.x_m, std::cos(yaw) * sp * sr - std::sin(yaw) * cr, 1e-12);
  EXPECT_NEAR(ry.y_m, std::sin(yaw) * sp * sr + std::cos(yaw) * cr, 1e-12);
  EXPECT_NEAR(ry.z_m, cp * sr, 1e-12);
}

TEST(OdometryIntegrator, PerFrameDecodingAndIntegrationAllocateNothing) {
  auto integrator = OdometryIntegrator::Create({}).value();
  SampleAssembler assembler;
  Simulated sim;
  sim.w = 0.1;
  std::vector<std::array<CanFrame, 3>> frames;
  for (int i = 0; i < 1000; ++i) frames.push_back(EncodeOdomSample(sim.Next().values));
  char line[kMaxCandumpLine];
  std::uint64_t poses = 0;
  test::AllocationScope scope;
  for (const auto& f : frames) {
    for (const CanFrame& frame : f) {
      const std::size_t n = FormatCandumpLine(UnixTime(), "can0", frame, CandumpPrecision::kMicroseconds, line).value();
      const CandumpLine parsed = ParseCandumpLine({line, n}).value();
      auto decoded = DecodeOdomFrame(parsed.frame);
      if (decoded && assembler.Add(*decoded, parsed.stamp)) poses += integrator.Add(assembler.sample()).has_value();
    }
  }
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_EQ(poses, 1000u);
}


TEST(OdometryStream, EveryBadFrameIsCountedByKind) {
  auto stream = OdometryStream::Create({}).value();
  Simulated sim;
  int poses = 0;
  for (int i = 0; i < 50; ++i) {
    const OdomSample s = sim.Next();
    auto frames = EncodeOdomSample(s.values);
    if (i == 10) frames[0].data[1] ^= 0x40;  // CRC failure: sample 10 is lost and bridged
    if (i == 20) frames[1].length = 6;        // bad length: sample 20 is lost and bridged
    for (const CanFrame& f : frames) poses += stream.Add(f, s.receive_time);
    CanFrame foreign;
    foreign.id = 0x343;
    foreign.length = 8;
    static_cast<void>(stream.Add(foreign, s.receive_time));
    if (i == 30) {
      CanFrame error;
      error.error = true;
      static_cast<void>(stream.Add(error, s.receive_time));
    }
  }
  const auto stats = stream.stats();
  EXPECT_EQ(poses, 48);
  EXPECT_EQ(stats.frames, 50u * 4u + 1u);
  EXPECT_EQ(stats.foreign_ids, 50u);
  EXPECT_EQ(stats.crc_errors, 1u);
  EXPECT_EQ(stats.bad_frames, 2u);
  EXPECT_EQ(stats.pairing.incomplete_samples, 2u);
  EXPECT_EQ(stats.integration.missing_samples, 2u);
  EXPECT_NEAR(stream.pose().T_odom_base.x_m, 49 * 0.02, 1e-6) << "lost samples are bridged, not dropped";
}

// ---- candump -----------------------------------------------------------------------------------

TEST(Candump, ParsesClassicFramesWithSixOrNineDecimals) {
  auto l = ParseCandumpLine("(1700000000.123456) can0 120#1A2B3C4D5E6F7788").value();
  EXPECT_EQ(l.kind, CandumpLine::Kind::kFrame);
  EXPECT_EQ(l.stamp.nanoseconds_since_epoch(), 1'700'000'000'123'456'000);
  EXPECT_EQ(l.interface_name(), "can0");
  EXPECT_EQ(l.frame.id, 0x120u);
  EXPECT_FALSE(l.frame.extended);
  EXPECT_EQ(l.frame.length, 8);
  EXPECT_EQ(l.frame.data[0], 0x1A);
  EXPECT_EQ(l.frame.data[7], 0x88);
  l = ParseCandumpLine("(1700000000.123456789)   vcan12 12345678#11.22.33 R\n").value();
  EXPECT_EQ(l.stamp.nanoseconds_since_epoch(), 1'700'000'000'123'456'789);
  EXPECT_TRUE(l.frame.extended);
  EXPECT_EQ(l.frame.id, 0x12345678u);
  EXPECT_EQ(l.frame.length, 3);
  l = ParseCandumpLine("(0000000001.000000) can0 123#").value();
  EXPECT_EQ(l.frame.length, 0);
  l = ParseCandumpLine("(0000000001.000000) can0 123#R7").value();
  EXPECT_TRUE(l.frame.remote);
  EXPECT_EQ(l.frame.length, 7);
  l = ParseCandumpLine("(0000000001.000000) can0 123#1122334455667788_E").value();
  EXPECT_EQ(l.frame.length, 8);
  l = ParseCandumpLine("(0000000001.000000) can0 20000080#0000000000000000").value();
  EXPECT_TRUE(l.frame.error);
}

TEST(Candump, CommentsFdAndXlAreSkippedCleanly) {
  EXPECT_EQ(ParseCandumpLine("").value().kind, CandumpLine::Kind::kComment);
  EXPECT_EQ(ParseCandumpLine("# recorded on robot 2").value().kind, CandumpLine::Kind::kComment);
  EXPECT_EQ(ParseCandumpLine("(1613656104.501098) can2 14C##16A0FFE00606E022400000000000000A0FFFF00FFFF").value().kind,
            CandumpLine::Kind::kCanFd);
  EXPECT_EQ(ParseCandumpLine("(1613656104.501098) can2 123##5").value().kind, CandumpLine::Kind::kCanFd);
  EXPECT_EQ(ParseCandumpLine("(1613656104.501098) can2 45123#81:00:12345678#11223344.556677").value().kind,
            CandumpLine::Kind::kCanXl);
}

TEST(Candump, MalformedLinesGiveAReason) {
  for (const char* bad : {
           "(1700000000.12345) can0 120#00",         // 5 decimals
           "(1700000000.1234567) can0 120#00",       // 7 decimals
           "(1700000000.123456 can0 120#00",         // no ')'
           "(17000x0000.123456) can0 120#00",        // not decimal
           "(1700000000.123456)",                    // nothing after the time
           "(1700000000.123456) can0",               // no frame
           "(1700000000.123456) can0 1200#00",       // 4-digit id
           "(1700000000.123456) can0 800#00",        // 11-bit overflow
           "(1700000000.123456) can0 12G#00",        // not hex
           "(1700000000.123456) can0 120#0",         // odd nibble
           "(1700000000.123456) can0 120#001122334455667788",  // 9 bytes
           "(1700000000.123456) can0 120#00 X",      // junk after
           "(1700000000.123456) can0 120#R9",        // RTR length
           "(1700000000.123456) averyveryverylongifname 120#00",
           "(160977999230.000000) can0 120#00",      // int64 nanosecond overflow (fuzzer find)
       }) {
    auto r = ParseCandumpLine(bad);
    ASSERT_FALSE(r.has_value()) << bad;
    EXPECT_EQ(r.error().code, Errc::kMalformed) << bad;
    EXPECT_STRNE(r.error().detail, "") << bad;
  }
}

TEST(Candump, FormatMatchesCandumpAndRoundTrips) {
  CanFrame f;
  f.id = 0x122;
  f.length = 8;
  f.data = {0x20, 0x4E, 0x00, 0x00, 0x01, 0x00, 0x05, 0xAB};
  char line[kMaxCandumpLine];
  const UnixTime t = UnixTime::FromNanoseconds(1'700'000'000'000'001'000);
  std::size_t n = FormatCandumpLine(t, "can0", f, CandumpPrecision::kMicroseconds, line).value();
  EXPECT_EQ(std::string(line, n), "(1700000000.000001) can0 122#204E0000010005AB\n");
  n = FormatCandumpLine(t, "can0", f, CandumpPrecision::kNanoseconds, line).value();
  EXPECT_EQ(std::string(line, n), "(1700000000.000001000) can0 122#204E0000010005AB\n");
  const auto parsed = ParseCandumpLine({line, n}).value();
  EXPECT_EQ(parsed.stamp, t);
  EXPECT_EQ(parsed.frame.data, f.data);
  CanFrame ext;
  ext.id = 0x343;
  ext.extended = true;
  ext.length = 1;
  n = FormatCandumpLine(UnixTime(), "vcan0", ext, CandumpPrecision::kMicroseconds, line).value();
  EXPECT_EQ(std::string(line, n), "(0000000000.000000) vcan0 00000343#00\n");
}

std::string TempPath(const char* name) {
  return (std::filesystem::temp_directory_path() / (std::string("msgraphs_") + std::to_string(::getpid()) + name)).string();
}

TEST(CandumpFile, WriterAndReaderRoundTripWithCountedSkips) {
  const std::string path = TempPath("_odom.log");
  Simulated sim;
  {
    auto writer = CandumpFileWriter::Create(path.c_str(), CandumpPrecision::kMicroseconds).value();
    for (int i = 0; i < 100; ++i) {
      const OdomSample s = sim.Next();
      for (const CanFrame& f : EncodeOdomSample(s.values)) ASSERT_TRUE(writer.Write(s.receive_time, "can0", f));
    }
    ASSERT_TRUE(writer.Close());
  }
  {  // append lines a real log may contain
    FILE* f = std::fopen(path.c_str(), "a");
    std::fputs("# comment\n\n(1700000100.000000) can0 14C##1AABB\n(1700000100.000000) can0 12#00\n", f);
    std::fputs(("(1700000100.000000) can0 12" + std::string(2000, '3') + "\n").c_str(), f);
    std::fputs("(1700000100.000001) can0 7FF#01", f);  // last line without newline
    std::fclose(f);
  }
  auto reader = CandumpFileReader::Open(path.c_str()).value();
  CandumpLine line;
  SampleAssembler assembler;
  auto integrator = OdometryIntegrator::Create({}).value();
  int poses = 0, frames = 0;
  while (reader.Next(line).value()) {
    ++frames;
    auto d = DecodeOdomFrame(line.frame);
    if (d && assembler.Add(*d, line.stamp)) poses += integrator.Add(assembler.sample()).has_value();
  }
  EXPECT_EQ(frames, 301);
  EXPECT_EQ(poses, 100);
  EXPECT_EQ(reader.stats().comments, 2u);
  EXPECT_EQ(reader.stats().can_fd, 1u);
  EXPECT_EQ(reader.stats().malformed, 2u);
  EXPECT_EQ(reader.stats().lines, 306u);
  std::remove(path.c_str());
}

TEST(CandumpFile, CantoolsSampleLogParses) {
  std::filesystem::path path;
  MSGRAPHS_REQUIRE_DATA("can/cantools_readme_candump_abs.log", path);
  auto reader = CandumpFileReader::Open(path.c_str()).value();
  CandumpLine line;
  std::vector<CandumpLine> lines;
  while (reader.Next(line).value()) lines.push_back(line);
  ASSERT_EQ(lines.size(), 10u);
  EXPECT_EQ(reader.stats().malformed, 0u);
  EXPECT_EQ(lines[0].interface_name(), "vcan0");
  EXPECT_EQ(lines[0].frame.id, 0x343u);
  EXPECT_TRUE(lines[0].frame.extended);  // written with 8 id digits
  EXPECT_EQ(lines[0].stamp.nanoseconds_since_epoch(), 1'609'779'922'655'421'000);
  // ABS DBC: four little-endian 16-bit wheel speeds at 0.015625 m/s.
  auto speed = [](const CanFrame& f, int i) {
    return (f.data[static_cast<std::size_t>(2 * i)] | (f.data[static_cast<std::size_t>(2 * i + 1)] << 8)) * 0.015625;
  };
  EXPECT_DOUBLE_EQ(speed(lines[0].frame, 0), 18.78125);
  EXPECT_DOUBLE_EQ(speed(lines[0].frame, 1), 18.890625);
  EXPECT_DOUBLE_EQ(speed(lines[0].frame, 2), 18.4375);
  EXPECT_DOUBLE_EQ(speed(lines[1].frame, 0), 20.28125);
  EXPECT_DOUBLE_EQ(speed(lines[1].frame, 3), 20.390625);
  // Not odometry: every frame is classified as a foreign id.
  for (const auto& l : lines) EXPECT_EQ(DecodeOdomFrame(l.frame).error().code, Errc::kNotFound);
}

}  // namespace
}  // namespace msgraphs::drivers::can_odometry
