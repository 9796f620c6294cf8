// SPDX-License-Identifier: MIT
#include <gpiod.h>

#include <cerrno>
#include <cstdlib>
#include <ctime>

#include "msgraphs/drivers/gpio/gpio.hpp"
#include "msgraphs/platform/clock.hpp"

namespace msgraphs::drivers::gpio {
namespace {

Error FromErrno(int e, const char* what) {
  if (e == EACCES || e == EPERM) return Error{Errc::kPermissionDenied, what, e};
  if (e == ENOENT || e == ENODEV || e == EINVAL) return Error{Errc::kNotFound, what, e};
  return Error{Errc::kIo, what, e};
}

// One requested line and the chip it belongs to; releases both on destruction.
class RequestedLine {
 public:
  RequestedLine(gpiod_chip* chip, gpiod_line* line) : chip_(chip), line_(line) {}
  RequestedLine(const RequestedLine&) = delete;
  RequestedLine& operator=(const RequestedLine&) = delete;
  ~RequestedLine() {
    if (line_ != nullptr) gpiod_line_release(line_);
    if (chip_ != nullptr) gpiod_chip_close(chip_);
  }
  gpiod_line* line() const { return line_; }

 private:
  gpiod_chip* chip_;
  gpiod_line* line_;
};

Expected<std::unique_ptr<RequestedLine>> Lookup(const GpioLineSpec& spec) {
  if (Status s = spec.Validate(); !s) return s.error();
  gpiod_chip* chip = gpiod_chip_open_lookup(spec.chip.c_str());
  if (chip == nullptr) return FromErrno(errno, "gpio: cannot open the GPIO chip");
  gpiod_line* line = nullptr;
  char* end = nullptr;
  const unsigned long offset = std::strtoul(spec.line.c_str(), &end, 10);
  if (end != nullptr && *end == '\0' && !spec.line.empty()) {
    line = gpiod_chip_get_line(chip, static_cast<unsigned>(offset));
  } else {
    line = gpiod_chip_find_line(chip, spec.line.c_str());
  }
  if (line == nullptr) {
    const int e = errno;
    gpiod_chip_close(chip);
    return FromErrno(e == 0 ? ENOENT : e, "gpio: no such line on the chip");
  }
  return std::make_unique<RequestedLine>(chip, line);
}

class LibgpiodOutput : public DigitalOutput {
 public:
  explicit LibgpiodOutput(std::unique_ptr<RequestedLine> line) : line_(std::move(line)) {}
  Status Set(bool active) override {
    if (gpiod_line_set_value(line_->line(), active ? 1 : 0) != 0) {
      return FromErrno(errno, "gpio: set value failed");
    }
    return Ok();
  }
  Expected<bool> Get() override {
    const int v = gpiod_line_get_value(line_->line());
    if (v < 0) return FromErrno(errno, "gpio: get value failed");
    return v != 0;
  }

 private:
  std::unique_ptr<RequestedLine> line_;
};

class LibgpiodInput : public EdgeInput {
 public:
  explicit LibgpiodInput(std::unique_ptr<RequestedLine> line) : line_(std::move(line)) {}
  Expected<bool> WaitEvent(SteadyTime deadline, EdgeEvent& event) override {
    for (;;) {
      const timespec timeout = platform::RemainingUntil(deadline);
      const int rc = gpiod_line_event_wait(line_->line(), &timeout);
      if (rc < 0) {
        if (errno == EINTR) continue;
        return FromErrno(errno, "gpio: event wait failed");
      }
      if (rc == 0) return false;
      gpiod_line_event raw{};
      if (gpiod_line_event_read(line_->line(), &raw) != 0) {
        return FromErrno(errno, "gpio: event read failed");
      }
      // libgpiod 1.6 events carry the kernel's CLOCK_MONOTONIC stamp, SteadyTime's clock.
      event.time = SteadyTime::FromNanoseconds(static_cast<std::int64_t>(raw.ts.tv_sec) * 1'000'000'000 +
                                               raw.ts.tv_nsec);
      event.rising = raw.event_type == GPIOD_LINE_EVENT_RISING_EDGE;
      return true;
    }
  }
  Expected<bool> Read() override {
    const int v = gpiod_line_get_value(line_->line());
    if (v < 0) return FromErrno(errno, "gpio: get value failed");
    return v != 0;
  }

 private:
  std::unique_ptr<RequestedLine> line_;
};

class LibgpiodProvider : public GpioProvider {
 public:
  Expected<std::unique_ptr<DigitalOutput>> OpenOutput(const GpioLineSpec& spec, const char* consumer,
                                                      bool initially_active) override {
    auto line = Lookup(spec);
    if (!line) return line.error();
    const int flags = spec.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
    if (gpiod_line_request_output_flags((*line)->line(), consumer, flags, initially_active ? 1 : 0) != 0) {
      return FromErrno(errno == EBUSY ? EBUSY : errno, "gpio: cannot request the line as output (busy?)");
    }
    return std::unique_ptr<DigitalOutput>(std::make_unique<LibgpiodOutput>(std::move(*line)));
  }

  Expected<std::unique_ptr<EdgeInput>> OpenEdgeInput(const GpioLineSpec& spec, const char* consumer,
                                                     Edge edge) override {
    auto line = Lookup(spec);
    if (!line) return line.error();
    const int flags = spec.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
    int rc = 0;
    switch (edge) {
      case Edge::kRising: rc = gpiod_line_request_rising_edge_events_flags((*line)->line(), consumer, flags); break;
      case Edge::kFalling: rc = gpiod_line_request_falling_edge_events_flags((*line)->line(), consumer, flags); break;
      case Edge::kBoth: rc = gpiod_line_request_both_edges_events_flags((*line)->line(), consumer, flags); break;
    }
    if (rc != 0) return FromErrno(errno, "gpio: cannot request edge events on the line");
    return std::unique_ptr<EdgeInput>(std::make_unique<LibgpiodInput>(std::move(*line)));
  }
};

}  // namespace

Status GpioLineSpec::Validate() const {
  if (chip.empty()) return Error{Errc::kInvalidConfig, "gpio: empty chip"};
  if (line.empty()) return Error{Errc::kInvalidConfig, "gpio: empty line"};
  return Ok();
}

std::unique_ptr<GpioProvider> MakeLibgpiodProvider() { return std::make_unique<LibgpiodProvider>(); }

}  // namespace msgraphs::drivers::gpio
