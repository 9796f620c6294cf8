// SPDX-License-Identifier: MIT
// What the kernel attaches to a received datagram or CAN frame: its receive timestamp
// (SO_TIMESTAMPNS) and the socket's running count of dropped messages (SO_RXQ_OVFL). Shared by
// the UDP receiver and the SocketCAN source.
#pragma once

#include <sys/socket.h>

#include <cstdint>
#include <ctime>

#include "msgraphs/base/time.hpp"

namespace msgraphs::platform {

/// Control-message space for one message's timestamp and drop counter.
inline constexpr std::size_t kReceiveControlBytes = CMSG_SPACE(sizeof(timespec)) + CMSG_SPACE(sizeof(std::uint32_t));

struct ReceiveMetadata {
  bool has_time = false;
  UnixTime time;  ///< CLOCK_REALTIME when the kernel received it
  bool has_drop_count = false;
  std::uint32_t drop_count = 0;  ///< cumulative per socket, wraps at 2^32
};

ReceiveMetadata ParseReceiveMetadata(const msghdr& message);

/// Adds the increase of the socket's wrapping drop counter to `total`, remembering the last value.
inline void AccumulateDrops(const ReceiveMetadata& m, std::uint32_t& last, std::uint64_t& total) {
  if (!m.has_drop_count) return;
  total += static_cast<std::uint32_t>(m.drop_count - last);
  last = m.drop_count;
}

}  // namespace msgraphs::platform
