// SPDX-License-Identifier: MIT
// GPIO lines behind a small interface: outputs (status LEDs) and edge-event inputs (a sync or
// trigger signal). LibgpiodProvider drives real lines through libgpiod 1.6 (the Linux GPIO
// character device); FakeGpioProvider is an in-memory stand-in for unit tests and for running
// without hardware. Lines are named in configuration by chip and line name or number.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/time.hpp"

namespace msgraphs::drivers::gpio {

struct GpioLineSpec {
  /// Chip: a name ("gpiochip0"), a path ("/dev/gpiochip0"), a label ("gpio-sim.0-node0") or
  /// a number ("0"), as libgpiod's gpiod_chip_open_lookup accepts.
  std::string chip = "gpiochip0";
  /// Line: a line name from the device tree or a decimal offset on the chip.
  std::string line = "0";
  bool active_low = false;

  Status Validate() const;
};

enum class Edge : std::uint8_t { kRising, kFalling, kBoth };

struct EdgeEvent {
  SteadyTime time;  ///< kernel timestamp (CLOCK_MONOTONIC, the clock SteadyTime uses)
  bool rising = true;
};

class DigitalOutput {
 public:
  virtual ~DigitalOutput() = default;
  /// Drives the line to its active (true) or inactive level (active_low is applied).
  virtual Status Set(bool active) = 0;
  virtual Expected<bool> Get() = 0;
};

class EdgeInput {
 public:
  virtual ~EdgeInput() = default;
  /// true: `event` holds the next edge; false: the deadline passed without one.
  virtual Expected<bool> WaitEvent(SteadyTime deadline, EdgeEvent& event) = 0;
  virtual Expected<bool> Read() = 0;
};

class GpioProvider {
 public:
  virtual ~GpioProvider() = default;
  virtual Expected<std::unique_ptr<DigitalOutput>> OpenOutput(const GpioLineSpec& spec,
                                                              const char* consumer,
                                                              bool initially_active) = 0;
  virtual Expected<std::unique_ptr<EdgeInput>> OpenEdgeInput(const GpioLineSpec& spec,
                                                             const char* consumer, Edge edge) = 0;
};

/// Real lines via libgpiod. kNotFound for a missing chip or line, kPermissionDenied when the
/// character device is not accessible, kIo when the line is busy.
std::unique_ptr<GpioProvider> MakeLibgpiodProvider();

}  // namespace msgraphs::drivers::gpio
