// SPDX-License-Identifier: MIT
// In-memory GPIO for tests and hardware-free runs: outputs remember their level and count
// changes; inputs are driven by the test, which queues edges.
#pragma once

#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "msgraphs/drivers/gpio/gpio.hpp"

namespace msgraphs::drivers::gpio {

class FakeGpioProvider : public GpioProvider {
 public:
  struct LineState {
    bool requested = false;
    bool active_low = false;
    bool physical_level = false;  ///< the electrical level (after active_low)
    std::uint64_t changes = 0;
    std::deque<EdgeEvent> pending_edges;
  };

  Expected<std::unique_ptr<DigitalOutput>> OpenOutput(const GpioLineSpec& spec,
                                                      const char* consumer,
                                                      bool initially_active) override;
  Expected<std::unique_ptr<EdgeInput>> OpenEdgeInput(const GpioLineSpec& spec,
                                                     const char* consumer,
                                                     Edge edge) override;

  /// Drives an input line to a physical level; queues an edge event if it changed and the
  /// requested edge matches.
  void Drive(const GpioLineSpec& spec, bool physical_level, SteadyTime time);
  /// Physical level and change count of a line (any line; unknown lines read low).
  bool PhysicalLevel(const GpioLineSpec& spec);
  std::uint64_t Changes(const GpioLineSpec& spec);

 private:
  friend class FakeLineClaim;
  struct Line : LineState {
    Edge edge = Edge::kBoth;
  };
  static std::string Key(const GpioLineSpec& spec) { return spec.chip + "/" + spec.line; }
  /// The line for spec, created if new; mutex_ must be held.
  std::shared_ptr<Line>& LineFor(const GpioLineSpec& spec);
  /// Marks the line requested with spec's polarity, or fails if it already is; mutex_ must be held.
  Expected<std::shared_ptr<Line>> Claim(const GpioLineSpec& spec);

  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Line>> lines_;
};

}  // namespace msgraphs::drivers::gpio
