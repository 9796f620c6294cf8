// SPDX-License-Identifier: MIT
// SocketCAN raw sockets: a receiver with an id filter, kernel timestamps and counters for error
// frames and kernel drops, and a sender (tools, tests, bench rigs). Linux only.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/fixed_vector.hpp"
#include "msgraphs/base/time.hpp"
#include "msgraphs/drivers/can_odometry/can_frame.hpp"
#include "msgraphs/drivers/can_odometry/candump.hpp"

namespace msgraphs::drivers::can_odometry {

struct SocketCanConfig {
  std::array<char, kMaxInterfaceName> interface{'c', 'a', 'n', '0'};
  /// Standard ids to receive (exact match). Empty: receive everything.
  FixedVector<std::uint32_t, 16> filter_ids;
  bool receive_error_frames = true;
  int receive_buffer_bytes = 1 << 20;
  std::size_t batch = 32;

  /// The odometry DBC's three ids on `interface`.
  static SocketCanConfig Odometry(std::string_view interface);
  Status Validate() const;
};

struct TimedCanFrame {
  UnixTime kernel_time;
  CanFrame frame;
};

struct SocketCanStats {
  std::uint64_t frames = 0;        ///< data frames delivered
  std::uint64_t error_frames = 0;  ///< CAN error frames (bus errors, controller problems)
  std::uint64_t bus_off = 0;       ///< error frames reporting bus-off
  std::uint64_t kernel_drops = 0;  ///< SO_RXQ_OVFL: frames lost to a full socket buffer
  std::uint64_t fd_frames = 0;     ///< CAN FD frames (not expected with a classic filter)
};

class SocketCanSource {
 public:
  /// kUnsupported when the kernel has no AF_CAN, kNotFound when the interface does not exist.
  static Expected<SocketCanSource> Open(const SocketCanConfig& config);

  /// Returns the number of data frames available through frame(i) (error frames are only
  /// counted), waiting until `deadline` for the first; 0 on timeout.
  Expected<std::size_t> Receive(SteadyTime deadline);
  const TimedCanFrame& frame(std::size_t i) const;
  const SocketCanStats& stats() const { return stats_; }

  SocketCanSource(SocketCanSource&&) noexcept;
  SocketCanSource& operator=(SocketCanSource&&) = delete;
  ~SocketCanSource();

 private:
  struct Buffers;
  SocketCanSource(int fd, std::size_t batch);
  int fd_ = -1;
  std::size_t batch_;
  std::unique_ptr<Buffers> buffers_;
  std::size_t ready_ = 0;
  std::uint32_t last_overflow_ = 0;
  SocketCanStats stats_;
};

class SocketCanSender {
 public:
  static Expected<SocketCanSender> Open(std::string_view interface);
  Status Send(const CanFrame& frame);

  SocketCanSender(SocketCanSender&&) noexcept;
  SocketCanSender& operator=(SocketCanSender&&) = delete;
  ~SocketCanSender();

 private:
  explicit SocketCanSender(int fd) : fd_(fd) {}
  int fd_ = -1;
};

}  // namespace msgraphs::drivers::can_odometry
