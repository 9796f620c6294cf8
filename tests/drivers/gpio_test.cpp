// SPDX-License-Identifier: MIT
// GPIO: the fake provider, the status LED patterns, and libgpiod's errors on a machine
// without the requested chip. The real lines are tested in kernel_in_the_loop_test.cpp.
#include <gtest/gtest.h>

#include "msgraphs/drivers/gpio/fake_gpio.hpp"
#include "msgraphs/drivers/gpio/status_led.hpp"
#include "msgraphs/platform/clock.hpp"

namespace msgraphs::drivers::gpio {
namespace {

TEST(FakeGpio, OutputsHonourActiveLowAndCountChanges) {
  FakeGpioProvider gpio;
  GpioLineSpec led{"chip0", "status_led", true};
  auto out = gpio.OpenOutput(led, "test", false).value();
  EXPECT_TRUE(gpio.PhysicalLevel(led)) << "inactive on an active-low line is electrically high";
  ASSERT_TRUE(out->Set(true));
  EXPECT_FALSE(gpio.PhysicalLevel(led));
  EXPECT_TRUE(out->Get().value());
  EXPECT_EQ(gpio.Changes(led), 1u);
  EXPECT_EQ(gpio.OpenOutput(led, "other", false).error().code, Errc::kIo) << "busy";
}

TEST(FakeGpio, InputsDeliverRequestedEdges) {
  FakeGpioProvider gpio;
  GpioLineSpec sync{"chip0", "3", false};
  auto in = gpio.OpenEdgeInput(sync, "test", Edge::kRising).value();
  const SteadyTime t = platform::SteadyNow();
  gpio.Drive(sync, true, t);
  gpio.Drive(sync, false, t + Duration::FromMilliseconds(1));  // falling: not requested
  EdgeEvent e;
  ASSERT_TRUE(in->WaitEvent(platform::SteadyNow() + Duration::FromMilliseconds(100), e).value());
  EXPECT_TRUE(e.rising);
  EXPECT_EQ(e.time, t);
  EXPECT_FALSE(in->WaitEvent(platform::SteadyNow() + Duration::FromMilliseconds(5), e).value());
  EXPECT_FALSE(in->Read().value());
}

TEST(StatusLed, PatternsAreDistinct) {
  auto at = [](int ms) { return Duration::FromMilliseconds(ms); };
  // ok: on except 100 ms every 2 s.
  EXPECT_TRUE(LedLevel(Health::kOk, at(0)));
  EXPECT_TRUE(LedLevel(Health::kOk, at(1899)));
  EXPECT_FALSE(LedLevel(Health::kOk, at(1950)));
  // starting 2 Hz, degraded 1 Hz, fault 5 Hz, all 50 %.
  EXPECT_TRUE(LedLevel(Health::kStarting, at(100)));
  EXPECT_FALSE(LedLevel(Health::kStarting, at(300)));
  EXPECT_TRUE(LedLevel(Health::kDegraded, at(400)));
  EXPECT_FALSE(LedLevel(Health::kDegraded, at(600)));
  EXPECT_TRUE(LedLevel(Health::kFault, at(50)));
  EXPECT_FALSE(LedLevel(Health::kFault, at(150)));
  EXPECT_FALSE(LedLevel(Health::kOff, at(0)));
}

TEST(StatusLed, WritesOnlyOnChangeAndSurvivesAFailingLine) {
  FakeGpioProvider gpio;
  GpioLineSpec spec{"chip0", "led", false};
  auto out = gpio.OpenOutput(spec, "test", false).value();
  StatusLed led(*out);
  const SteadyTime t0 = SteadyTime::FromNanoseconds(1'000'000'000);
  led.SetHealth(Health::kFault, t0);
  for (int ms = 0; ms < 1000; ms += 10) led.Update(t0 + Duration::FromMilliseconds(ms));
  EXPECT_EQ(led.writes(), 10u) << "5 Hz for 1 s: 10 level changes";
  EXPECT_EQ(gpio.Changes(spec), 10u);

  class Broken : public DigitalOutput {
   public:
    Status Set(bool) override { return Error{Errc::kIo, "gpio: gone"}; }
    Expected<bool> Get() override { return Error{Errc::kIo, "gpio: gone"}; }
  } broken;
  StatusLed bad(broken);
  bad.SetHealth(Health::kOk, t0);
  bad.Update(t0 + Duration::FromMilliseconds(10));
  EXPECT_GE(bad.write_errors(), 2u);
}

TEST(LibgpiodProvider, MissingChipIsNotFound) {
  auto gpio = MakeLibgpiodProvider();
  auto out = gpio->OpenOutput({"no-such-gpiochip-xyz", "0", false}, "test", false);
  ASSERT_FALSE(out.has_value());
  EXPECT_EQ(out.error().code, Errc::kNotFound);
  EXPECT_EQ(gpio->OpenOutput({"", "0", false}, "test", false).error().code, Errc::kInvalidConfig);
}

}  // namespace
}  // namespace msgraphs::drivers::gpio
