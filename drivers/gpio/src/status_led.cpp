// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/gpio/status_led.hpp"

namespace msgraphs::drivers::gpio {
namespace {
bool Square(Duration since, std::int64_t period_ms) {
  const std::int64_t phase_ms = (since.nanoseconds() / 1'000'000) % period_ms;
  return phase_ms < period_ms / 2;
}
}  // namespace

bool LedLevel(Health health, Duration since_start) {
  if (since_start < Duration()) since_start = Duration();
  switch (health) {
    case Health::kStarting: return Square(since_start, 500);
    case Health::kDegraded: return Square(since_start, 1000);
    case Health::kFault: return Square(since_start, 200);
    case Health::kOk: return (since_start.nanoseconds() / 1'000'000) % 2000 < 1900;
    case Health::kOff: return false;
  }
  return false;
}

void StatusLed::SetHealth(Health health, SteadyTime now) {
  if (health == health_) return;
  health_ = health;
  pattern_start_ = now;
  Update(now);
}

void StatusLed::Update(SteadyTime now) {
  const bool level = LedLevel(health_, now - pattern_start_);
  if (level_known_ && level == level_) return;
  if (output_.Set(level)) {
    level_ = level;
    level_known_ = true;
    ++writes_;
  } else {
    ++write_errors_;
  }
}

}  // namespace msgraphs::drivers::gpio
