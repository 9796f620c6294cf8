// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/gpio/fake_gpio.hpp"

#include <thread>

#include "msgraphs/platform/clock.hpp"

namespace msgraphs::drivers::gpio {

class FakeOutput : public DigitalOutput {
 public:
  FakeOutput(FakeGpioProvider& owner, std::shared_ptr<FakeGpioProvider::Line> line)
      : owner_(owner), line_(std::move(line)) {}
  ~FakeOutput() override {
    std::lock_guard lock(owner_.mutex_);
    line_->requested = false;
  }
  Status Set(bool active) override {
    std::lock_guard lock(owner_.mutex_);
    const bool level = active != line_->active_low;
    if (level != line_->physical_level) ++line_->changes;
    line_->physical_level = level;
    return Ok();
  }
  Expected<bool> Get() override {
    std::lock_guard lock(owner_.mutex_);
    return line_->physical_level != line_->active_low;
  }

 private:
  FakeGpioProvider& owner_;
  std::shared_ptr<FakeGpioProvider::Line> line_;
};

class FakeInput : public EdgeInput {
 public:
  FakeInput(FakeGpioProvider& owner, std::shared_ptr<FakeGpioProvider::Line> line)
      : owner_(owner), line_(std::move(line)) {}
  ~FakeInput() override {
    std::lock_guard lock(owner_.mutex_);
    line_->requested = false;
  }
  Expected<bool> WaitEvent(SteadyTime deadline, EdgeEvent& event) override {
    for (;;) {
      {
        std::lock_guard lock(owner_.mutex_);
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
  Expected<bool> Read() override {
    std::lock_guard lock(owner_.mutex_);
    return line_->physical_level != line_->active_low;
  }

 private:
  FakeGpioProvider& owner_;
  std::shared_ptr<FakeGpioProvider::Line> line_;
};

Expected<std::unique_ptr<DigitalOutput>> FakeGpioProvider::OpenOutput(const GpioLineSpec& spec,
                                                                      const char* /*consumer*/,
                                                                      bool initially_active) {
  if (Status s = spec.Validate(); !s) return s.error();
  std::lock_guard lock(mutex_);
  auto& line = lines_[Key(spec)];
  if (!line) line = std::make_shared<Line>();
  if (line->requested) return Error{Errc::kIo, "gpio: line busy (already requested)"};
  line->requested = true;
  line->active_low = spec.active_low;
  line->physical_level = initially_active != spec.active_low;
  return std::unique_ptr<DigitalOutput>(std::make_unique<FakeOutput>(*this, line));
}

Expected<std::unique_ptr<EdgeInput>> FakeGpioProvider::OpenEdgeInput(const GpioLineSpec& spec,
                                                                     const char* /*consumer*/, Edge edge) {
  if (Status s = spec.Validate(); !s) return s.error();
  std::lock_guard lock(mutex_);
  auto& line = lines_[Key(spec)];
  if (!line) line = std::make_shared<Line>();
  if (line->requested) return Error{Errc::kIo, "gpio: line busy (already requested)"};
  line->requested = true;
  line->active_low = spec.active_low;
  line->edge = edge;
  return std::unique_ptr<EdgeInput>(std::make_unique<FakeInput>(*this, line));
}

void FakeGpioProvider::Drive(const GpioLineSpec& spec, bool physical_level, SteadyTime time) {
  std::lock_guard lock(mutex_);
  auto& line = lines_[Key(spec)];
  if (!line) line = std::make_shared<Line>();
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
