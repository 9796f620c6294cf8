// SPDX-License-Identifier: MIT
// Kernel-in-the-loop tests: the real SocketCAN and libgpiod code against a real kernel's vcan0
// and gpio-sim. ctest runs this binary inside a qemu-system VM (scripts/vm/vm-run.sh, label
// `vm`) with MSGRAPHS_REQUIRE_HARDWARE=1, where a missing device is a failure. Run directly on
// a machine without vcan0 or gpio-sim, each test skips and says why; on one that has them
// (`ip link add vcan0 type vcan`, a live gpio-sim chip), it runs there too.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "msgraphs/drivers/can_odometry/candump_file.hpp"
#include "msgraphs/drivers/can_odometry/odometry_frames.hpp"
#include "msgraphs/drivers/can_odometry/odometry_integrator.hpp"
#include "msgraphs/drivers/can_odometry/socketcan.hpp"
#include "msgraphs/drivers/gpio/gpio.hpp"
#include "msgraphs/drivers/gpio/status_led.hpp"
#include "msgraphs/platform/clock.hpp"

namespace msgraphs::drivers {
namespace {

bool HardwareRequired() {
  const char* v = std::getenv("MSGRAPHS_REQUIRE_HARDWARE");
  return v != nullptr && std::string(v) == "1";
}

#define MSGRAPHS_NEED_DEVICE(condition, why)                                    \
  do {                                                                          \
    if (!(condition)) {                                                         \
      if (HardwareRequired()) FAIL() << "required device missing: " << (why);   \
      GTEST_SKIP() << (why);                                                    \
    }                                                                           \
  } while (0)

SteadyTime In(int ms) { return platform::SteadyNow() + Duration::FromMilliseconds(ms); }

TEST(SocketCan, OdometryFramesRoundTripThroughVcanWithFilterAndTimestamps) {
  using namespace can_odometry;
  auto source = SocketCanSource::Open(SocketCanConfig::Odometry("vcan0"));
  MSGRAPHS_NEED_DEVICE(source.has_value(),
                       std::string("SocketCAN vcan0 unavailable: ") + (source ? "" : source.error().detail));
  auto sender = SocketCanSender::Open("vcan0").value();

  const UnixTime before = platform::UnixNow();
  OdomSampleValues v;
  v.sample_time_us = 1000;
  for (int i = 0; i < 100; ++i) {
    v.sequence = static_cast<std::uint8_t>(i);
    v.sample_time_us += 20000;
    v.dx_m = 0.02;
    auto frames = EncodeOdomSample(v);
    if (i == 50) frames[1].data[3] ^= 0x01;  // corrupt one frame: CRC failure
    for (const CanFrame& f : frames) ASSERT_TRUE(sender.Send(f));
    CanFrame foreign;
    foreign.id = 0x123;  // not odometry: the kernel filter drops it
    foreign.length = 2;
    ASSERT_TRUE(sender.Send(foreign));
  }

  std::vector<TimedCanFrame> received;
  while (received.size() < 300) {
    const std::size_t n = source->Receive(In(2000)).value();
    ASSERT_GT(n, 0u) << "timed out after " << received.size() << " frames";
    for (std::size_t i = 0; i < n; ++i) received.push_back(source->frame(i));
  }
  EXPECT_EQ(source->Receive(In(100)).value(), 0u) << "the foreign id must be filtered";
  EXPECT_EQ(source->stats().frames, 300u);
  EXPECT_EQ(source->stats().kernel_drops, 0u);

  SampleAssembler assembler;
  auto integrator = OdometryIntegrator::Create({}).value();
  int crc_errors = 0, poses = 0;
  OdometryPose last;
  // Kernel receive stamps (SO_TIMESTAMPNS) are CLOCK_REALTIME, which the system may step: a
  // freshly booted VM once stepped it 7 ms back in the middle of this loop. The driver's part is
  // to hand on the kernel's stamp, so each must lie within the wall-clock window of the test
  // (a second either side covers any such step); their order is the clock's, counted and printed.
  const UnixTime after = platform::UnixNow();
  const Duration slack = Duration::FromSeconds(1.0);
  int steps_back = 0;
  for (std::size_t i = 0; i < received.size(); ++i) {
    const TimedCanFrame& t = received[i];
    EXPECT_GE(t.kernel_time, before - slack);
    EXPECT_LE(t.kernel_time, after + slack);
    if (i > 0 && t.kernel_time < received[i - 1].kernel_time) ++steps_back;
    auto d = DecodeOdomFrame(t.frame);
    if (!d) {
      crc_errors += d.error().code == Errc::kChecksum;
      continue;
    }
    if (assembler.Add(*d, t.kernel_time)) {
      last = integrator.Add(assembler.sample()).value();
      ++poses;
    }
  }
  if (steps_back > 0) std::printf("note: %d kernel stamps earlier than the one before (the realtime clock stepped)\n", steps_back);
  EXPECT_EQ(crc_errors, 1);
  EXPECT_EQ(poses, 99);
  EXPECT_EQ(assembler.stats().incomplete_samples, 1u);
  EXPECT_EQ(integrator.stats().missing_samples, 1u);
  EXPECT_NEAR(last.T_odom_base.x_m, 99 * 0.02, 1e-9) << "the lost sample is bridged";

  // What was received can be recorded as a candump log and read back identically.
  const std::string log = "kernel_in_the_loop_candump.log";
  {
    auto writer = CandumpFileWriter::Create(log.c_str(), CandumpPrecision::kNanoseconds).value();
    for (const auto& t : received) ASSERT_TRUE(writer.Write(t.kernel_time, "vcan0", t.frame));
    ASSERT_TRUE(writer.Close());
  }
  auto reader = CandumpFileReader::Open(log.c_str()).value();
  CandumpLine line;
  std::size_t k = 0;
  while (reader.Next(line).value()) {
    ASSERT_LT(k, received.size());
    EXPECT_EQ(line.stamp, received[k].kernel_time);
    EXPECT_EQ(line.frame.id, received[k].frame.id);
    EXPECT_EQ(line.frame.data, received[k].frame.data);
    ++k;
  }
  EXPECT_EQ(k, received.size());
  std::remove(log.c_str());
}

TEST(SocketCan, MissingInterfaceIsNotFound) {
  using namespace can_odometry;
  auto source = SocketCanSource::Open(SocketCanConfig::Odometry("vcan0"));
  MSGRAPHS_NEED_DEVICE(source.has_value(), "SocketCAN vcan0 unavailable");
  auto missing = SocketCanSource::Open(SocketCanConfig::Odometry("nocan7"));
  ASSERT_FALSE(missing.has_value());
  EXPECT_EQ(missing.error().code, Errc::kNotFound);
}

// The first live gpio-sim chip made by configfs (vm-run.sh makes chip0 with 8 lines).
struct SimChip {
  std::string chip_name;  // e.g. gpiochip0
  std::string sysfs;      // /sys/devices/platform/gpio-sim.0/gpiochip0
};

bool FindSimChip(SimChip& chip) {
  std::ifstream dev("/sys/kernel/config/gpio-sim/chip0/dev_name");
  std::ifstream name("/sys/kernel/config/gpio-sim/chip0/bank0/chip_name");
  std::string dev_name;
  if (!(dev >> dev_name) || !(name >> chip.chip_name)) return false;
  chip.sysfs = "/sys/devices/platform/" + dev_name + "/" + chip.chip_name;
  return true;
}

std::string ReadSim(const SimChip& chip, int line, const char* attribute) {
  std::ifstream f(chip.sysfs + "/sim_gpio" + std::to_string(line) + "/" + attribute);
  std::string value;
  f >> value;
  return value;
}

void WriteSim(const SimChip& chip, int line, const char* attribute, const char* value) {
  std::ofstream f(chip.sysfs + "/sim_gpio" + std::to_string(line) + "/" + attribute);
  f << value;
}

TEST(Gpio, OutputIsReadBackFromTheSimulatedChip) {
  SimChip chip;
  MSGRAPHS_NEED_DEVICE(FindSimChip(chip), "no live gpio-sim chip (configfs gpio-sim/chip0)");
  auto gpio = gpio::MakeLibgpiodProvider();
  auto out = gpio->OpenOutput({chip.chip_name, "0", false}, "msgraphs-test", false);
  ASSERT_TRUE(out.has_value()) << out.error().detail;
  EXPECT_EQ(ReadSim(chip, 0, "value"), "0");
  ASSERT_TRUE((*out)->Set(true));
  EXPECT_EQ(ReadSim(chip, 0, "value"), "1");
  ASSERT_TRUE((*out)->Set(false));
  EXPECT_EQ(ReadSim(chip, 0, "value"), "0");
  // The line is now ours: a second request is refused.
  EXPECT_FALSE(gpio->OpenOutput({chip.chip_name, "0", false}, "again", false).has_value());

  // Active-low: the status LED's "on" drives the line low.
  auto led_line = gpio->OpenOutput({chip.chip_name, "2", true}, "msgraphs-led", false).value();
  EXPECT_EQ(ReadSim(chip, 2, "value"), "1");
  gpio::StatusLed led(*led_line);
  const SteadyTime t0 = platform::SteadyNow();
  led.SetHealth(gpio::Health::kOk, t0);
  EXPECT_EQ(ReadSim(chip, 2, "value"), "0");
  led.Update(t0 + Duration::FromMilliseconds(1950));  // the ok pattern's short blink-off
  EXPECT_EQ(ReadSim(chip, 2, "value"), "1");
  EXPECT_EQ(led.write_errors(), 0u);
}

TEST(Gpio, InputEdgesAreSeenWithKernelTimestamps) {
  SimChip chip;
  MSGRAPHS_NEED_DEVICE(FindSimChip(chip), "no live gpio-sim chip (configfs gpio-sim/chip0)");
  auto gpio = gpio::MakeLibgpiodProvider();
  WriteSim(chip, 1, "pull", "pull-down");
  auto in = gpio->OpenEdgeInput({chip.chip_name, "1", false}, "msgraphs-sync", gpio::Edge::kBoth);
  ASSERT_TRUE(in.has_value()) << in.error().detail;
  EXPECT_FALSE((*in)->Read().value());

  const SteadyTime before = platform::SteadyNow();
  WriteSim(chip, 1, "pull", "pull-up");
  gpio::EdgeEvent e;
  ASSERT_TRUE((*in)->WaitEvent(In(2000), e).value()) << "no rising edge seen";
  EXPECT_TRUE(e.rising);
  EXPECT_GE(e.time, before);
  EXPECT_LE(e.time, platform::SteadyNow());
  EXPECT_TRUE((*in)->Read().value());

  WriteSim(chip, 1, "pull", "pull-down");
  ASSERT_TRUE((*in)->WaitEvent(In(2000), e).value()) << "no falling edge seen";
  EXPECT_FALSE(e.rising);
  EXPECT_FALSE((*in)->WaitEvent(In(50), e).value());
}

}  // namespace
}  // namespace msgraphs::drivers
