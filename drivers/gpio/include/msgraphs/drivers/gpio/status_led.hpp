// SPDX-License-Identifier: MIT
// Shows the node's health on one LED with patterns a person can tell apart from a few metres:
//   starting  2 Hz, 50 %          fault     5 Hz, 50 % (fast flicker)
//   ok        on, with a 100 ms blink-off every 2 s (steady light that proves the process lives)
//   degraded  1 Hz, 50 %          off       off (clean shutdown)
// Update() is called from any periodic loop; it writes the line only when the level changes.
#pragma once

#include <cstdint>

#include "msgraphs/base/time.hpp"
#include "msgraphs/drivers/gpio/gpio.hpp"

namespace msgraphs::drivers::gpio {

enum class Health : std::uint8_t { kStarting, kOk, kDegraded, kFault, kOff };

/// The LED level a health state shows at `since_start` (pure: unit-tested without a line).
bool LedLevel(Health health, Duration since_start);

class StatusLed {
 public:
  explicit StatusLed(DigitalOutput& output) : output_(output) {}

  void SetHealth(Health health, SteadyTime now);
  /// Writes the level due at `now`. Errors are counted, never fatal: a broken LED must not stop
  /// the robot.
  void Update(SteadyTime now);

  Health health() const { return health_; }
  std::uint64_t write_errors() const { return write_errors_; }
  std::uint64_t writes() const { return writes_; }

 private:
  DigitalOutput& output_;
  Health health_ = Health::kStarting;
  SteadyTime pattern_start_;
  bool level_known_ = false;
  bool level_ = false;
  std::uint64_t writes_ = 0;
  std::uint64_t write_errors_ = 0;
};

}  // namespace msgraphs::drivers::gpio
