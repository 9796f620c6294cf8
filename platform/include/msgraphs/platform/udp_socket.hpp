// SPDX-License-Identifier: MIT
// UDP sockets for sensor traffic: a batched receiver with kernel timestamps and loss counters,
// and a batched sender (used by the hardware-in-the-loop replay tool).
//
// All buffers are allocated at Open; Receive and Send never allocate.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/ipv4.hpp"
#include "msgraphs/base/time.hpp"

namespace msgraphs::platform {

struct UdpReceiverConfig {
  Ipv4Endpoint bind{kIpv4Any, 0};  ///< port 0 picks a free port (tests); see bound_port()
  /// Accept datagrams only from this address (0 = any). Others are counted as foreign.
  std::uint32_t expected_source = 0;
  /// Accept only payloads of exactly this size (0 = any size). Others are counted as foreign.
  std::size_t expected_payload_bytes = 0;
  /// Datagrams longer than this are truncated by the kernel; we count and drop them.
  std::size_t max_payload_bytes = 2048;
  /// Kernel receive buffer. 8 MiB holds ~6 s of VLP-16 data, so a late thread loses nothing.
  /// Above net.core.rmem_max it needs CAP_NET_ADMIN (SO_RCVBUFFORCE); we try both.
  int receive_buffer_bytes = 8 << 20;
  std::size_t batch = 64;  ///< datagrams per recvmmsg call
  bool allow_address_reuse = true;  ///< SO_REUSEADDR: several readers of a broadcast port

  Status Validate() const;
};

struct ReceivedDatagram {
  /// SO_TIMESTAMPNS: when the kernel received it (CLOCK_REALTIME); see stats().kernel_timestamps.
  UnixTime kernel_time;
  Ipv4Endpoint source;
  std::span<const std::uint8_t> payload;  ///< valid until the next Receive
};

struct UdpReceiverStats {
  std::uint64_t datagrams = 0;  ///< accepted
  std::uint64_t bytes = 0;
  std::uint64_t truncated = 0;  ///< longer than max_payload_bytes: dropped
  std::uint64_t foreign = 0;    ///< wrong source or size: dropped
  /// Datagrams the kernel dropped because the socket buffer was full (SO_RXQ_OVFL). The kernel
  /// reports drops with the next datagram it queues, so the count lags until traffic resumes.
  std::uint64_t kernel_drops = 0;
  std::uint64_t receive_calls = 0;
  std::size_t peak_batch = 0;
  int receive_buffer_bytes = 0;  ///< what the kernel granted (it reports twice the request)
  /// False where the kernel (or an emulator) refused SO_TIMESTAMPNS: times are then taken in
  /// user space when the batch is read, later and noisier.
  bool kernel_timestamps = true;
  /// False where SO_RXQ_OVFL was refused: kernel_drops then stays 0 whatever is lost.
  bool drop_counting = true;
};

class UdpReceiver {
 public:
  static Expected<UdpReceiver> Open(const UdpReceiverConfig& config);

  /// Returns the number of accepted datagrams now available through datagram(i), waiting until
  /// `deadline` for the first one. 0 means the deadline passed with nothing accepted.
  Expected<std::size_t> Receive(SteadyTime deadline);
  const ReceivedDatagram& datagram(std::size_t i) const;

  std::uint16_t bound_port() const { return bound_port_; }
  const UdpReceiverStats& stats() const { return stats_; }
  int fd() const { return fd_; }

  UdpReceiver(UdpReceiver&&) noexcept;
  UdpReceiver& operator=(UdpReceiver&&) = delete;
  UdpReceiver(const UdpReceiver&) = delete;
  ~UdpReceiver();

 private:
  struct Buffers;
  UdpReceiver(int fd, const UdpReceiverConfig& config);
  std::size_t ReceiveBatch(int& error_out);

  int fd_ = -1;
  UdpReceiverConfig config_;
  std::unique_ptr<Buffers> buffers_;
  std::size_t ready_ = 0;
  std::uint16_t bound_port_ = 0;
  std::uint32_t last_overflow_count_ = 0;
  UdpReceiverStats stats_;
};

/// Waits until one of `fds` is readable or the deadline passes; returns a bit mask of the
/// readable ones (bit i for fds[i], at most 32), 0 on timeout.
Expected<std::uint32_t> WaitReadable(std::span<const int> fds, SteadyTime deadline);

struct UdpSenderConfig {
  Ipv4Endpoint bind{kIpv4Any, 0};
  bool allow_broadcast = false;
  int send_buffer_bytes = 4 << 20;
  std::size_t batch = 64;
  std::size_t max_payload_bytes = 2048;
  Status Validate() const;
};

struct UdpSenderStats {
  std::uint64_t datagrams = 0;
  std::uint64_t bytes = 0;
  std::uint64_t would_block = 0;  ///< sends that found the socket buffer full (retried)
  std::uint64_t errors = 0;
};

class UdpSender {
 public:
  static Expected<UdpSender> Open(const UdpSenderConfig& config);

  /// Sends one datagram (blocking while the socket buffer is full).
  Status Send(const Ipv4Endpoint& destination, std::span<const std::uint8_t> payload);
  /// Queues a datagram for SendQueued (copied into a preallocated slot); kCapacityExceeded
  /// when `batch` datagrams are already queued.
  Status Queue(const Ipv4Endpoint& destination, std::span<const std::uint8_t> payload);
  /// Sends everything queued with sendmmsg.
  Status SendQueued();

  const UdpSenderStats& stats() const { return stats_; }

  UdpSender(UdpSender&&) noexcept;
  UdpSender& operator=(UdpSender&&) = delete;
  UdpSender(const UdpSender&) = delete;
  ~UdpSender();

 private:
  struct Buffers;
  UdpSender(int fd, const UdpSenderConfig& config);
  int fd_ = -1;
  UdpSenderConfig config_;
  std::unique_ptr<Buffers> buffers_;
  std::size_t queued_ = 0;
  UdpSenderStats stats_;
};

}  // namespace msgraphs::platform
