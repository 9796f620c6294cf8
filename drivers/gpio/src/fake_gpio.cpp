// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/gpio/fake_gpio.hpp"

#include <thread>

#include "msgraphs/platform/clock.hpp"

namespace msgraphs::drivers::gpio {

// A requested line: gives it back on destruction, so it can be requested again.
class FakeLineClaim {
 public:
  FakeLineClaim(std::mutex& mutex, std::shared_ptr<FakeGpioProvider::Line> line)
      : mutex_(mutex), line_(std::move(line)) {}
  ~FakeLineClaim() {
    std::lock_guard lock(mutex_);
    line_->requested = false;
  }
  FakeLineClaim(const FakeLineClaim&) = delete;
  FakeLineClaim& operator=(const FakeLineClaim&) = delete;

 protected:
  bool LogicalLevel() const {
    std::lock_guard lock(mutex_);
    return line_->physical_level != line_->active_low;
  }

  std::mutex& mutex_;
  std::shared_ptr<FakeGpioProvider::Line> line_;
};

namespace {

class FakeOutput : public DigitalOutput, private FakeLineClaim {
 public:
  using FakeLineClaim::FakeLineClaim;
  Status Set(bool active) override {
    std::lock_guard lock(mutex_);
    const bool level = active != line_->active_low;
    if (level != line_->physical_level) ++line_->changes;
    line_->physical_level = level;
    return Ok();
  }
  Expected<bool> Get() override { return LogicalLevel(); }
};

class FakeInput : public EdgeInput, private FakeLineClaim {
 public:
  using FakeLineClaim::FakeLineClaim;
  Expected<bool> WaitEvent(SteadyTime deadline, EdgeEvent& event) override {
    for (;;) {
      {
        std::lock_guard lock(mutex_);
        if (!line_->pending_edges.empty()) {
          event = line_->pending_edges.front();
          line_->pending_edges.pop_front();
          return true;
        }
      }
      if (platform::SteadyNow() >= deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  Expected<bool> Read() override { return LogicalLevel(); }
};

}  // namespace

std::shared_ptr<FakeGpioProvider::Line>& FakeGpioProvider::LineFor(const GpioLineSpec& spec) {
  auto& line = lines_[Key(spec)];
  if (!line) line = std::make_shared<Line>();
  return line;
}

Expected<std::shared_ptr<FakeGpioProvider::Line>> FakeGpioProvider::Claim(
    const GpioLineSpec& spec) {
  if (Status s = spec.Validate(); !s) return s.error();
  std::shared_ptr<Line>& line = LineFor(spec);
  if (line->requested) return Error{Errc::kIo, "gpio: line busy (already requested)"};
  line->requested = true;
  line->active_low = spec.active_low;
  return line;
}

Expected<std::unique_ptr<DigitalOutput>> FakeGpioProvider::OpenOutput(const GpioLineSpec& spec,
                                                                      const char* /*consumer*/,
                                                                      bool initially_active) {
  std::lock_guard lock(mutex_);
  Expected<std::shared_ptr<Line>> line = Claim(spec);
  if (!line) return line.error();
  (*line)->physical_level = initially_active != spec.active_low;
  return std::unique_ptr<DigitalOutput>(std::make_unique<FakeOutput>(mutex_, *line));
}

Expected<std::unique_ptr<EdgeInput>> FakeGpioProvider::OpenEdgeInput(const GpioLineSpec& spec,
                                                                     const char* /*consumer*/,
                                                                     Edge edge) {
  std::lock_guard lock(mutex_);
  Expected<std::shared_ptr<Line>> line = Claim(spec);
  if (!line) return line.error();
  (*line)->edge = edge;
  return std::unique_ptr<EdgeInput>(std::make_unique<FakeInput>(mutex_, *line));
}

void FakeGpioProvider::Drive(const GpioLineSpec& spec, bool physical_level, SteadyTime time) {
  std::lock_guard lock(mutex_);
  Line* line = LineFor(spec).get();
  if (line->physical_level == physical_level) return;
  line->physical_level = physical_level;
  ++line->changes;
  if (!line->requested) return;
  const bool rising = physical_level != line->active_low;  // edges of the logical level
  if (line->edge == Edge::kBoth || (line->edge == Edge::kRising) == rising) {
    line->pending_edges.push_back({time, rising});
  }
}

bool FakeGpioProvider::PhysicalLevel(const GpioLineSpec& spec) {
  std::lock_guard lock(mutex_);
  const auto it = lines_.find(Key(spec));
  return it != lines_.end() && it->second->physical_level;
}

std::uint64_t FakeGpioProvider::Changes(const GpioLineSpec& spec) {
  std::lock_guard lock(mutex_);
  const auto it = lines_.find(Key(spec));
  return it == lines_.end() ? 0 : it->second->changes;
}

}  // namespace msgraphs::drivers::gpio
