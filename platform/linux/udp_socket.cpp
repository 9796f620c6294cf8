// SPDX-License-Identifier: MIT
#include "msgraphs/platform/udp_socket.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "msgraphs/platform/clock.hpp"
#include "msgraphs/platform/receive_metadata.hpp"

namespace msgraphs::platform {
namespace {

sockaddr_in ToSockaddr(const Ipv4Endpoint& endpoint) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(endpoint.port);
  a.sin_addr.s_addr = htonl(endpoint.address);
  return a;
}

}  // namespace

// ---- receiver --------------------------------------------------------------------------------

struct UdpReceiver::Buffers {
  std::vector<std::uint8_t> payload;  // batch x (max_payload_bytes + 1)
  std::vector<std::uint8_t> control;  // batch x kReceiveControlBytes
  std::vector<mmsghdr> headers;
  std::vector<iovec> iov;
  std::vector<sockaddr_in> sources;
  std::vector<ReceivedDatagram> accepted;
};

Status UdpReceiverConfig::Validate() const {
  if (batch == 0 || batch > 1024) return Error{Errc::kInvalidConfig, "udp: batch must be 1..1024"};
  if (max_payload_bytes == 0 || max_payload_bytes > 65507) {
    return Error{Errc::kInvalidConfig, "udp: max payload must be 1..65507 bytes"};
  }
  if (expected_payload_bytes > max_payload_bytes) {
    return Error{Errc::kInvalidConfig, "udp: expected payload above max payload"};
  }
  if (receive_buffer_bytes < 0) return Error{Errc::kInvalidConfig, "udp: negative receive buffer"};
  return Ok();
}

Expected<UdpReceiver> UdpReceiver::Open(const UdpReceiverConfig& config) {
  if (Status s = config.Validate(); !s) return s.error();
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return Error{Errc::kIo, "udp: socket() failed", errno};
  UdpReceiver receiver(fd, config);
  const int one = 1;
  if (config.allow_address_reuse) {
    static_cast<void>(::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one)));
  }
  if (config.receive_buffer_bytes > 0) {
    const int want = config.receive_buffer_bytes;
    // FORCE ignores net.core.rmem_max but needs CAP_NET_ADMIN; fall back to the capped one.
    if (::setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &want, sizeof(want)) != 0) {
      static_cast<void>(::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &want, sizeof(want)));
    }
  }
  int granted = 0;
  socklen_t len = sizeof(granted);
  if (::getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &granted, &len) == 0) {
    receiver.stats_.receive_buffer_bytes = granted;
  }
  // Every Linux kernel has both options; emulators (qemu-user) may not translate them. Then
  // datagrams are stamped on arrival in user space and drops cannot be counted: the stats say so.
  receiver.stats_.kernel_timestamps =
      ::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof(one)) == 0;
  receiver.stats_.drop_counting = ::setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof(one)) == 0;
  const sockaddr_in address = ToSockaddr(config.bind);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    return Error{Errc::kIo, "udp: bind failed (port in use or not permitted)", errno};
  }
  sockaddr_in bound{};
  len = sizeof(bound);
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &len) == 0) {
    receiver.bound_port_ = ntohs(bound.sin_port);
  }
  return receiver;
}

UdpReceiver::UdpReceiver(int fd, const UdpReceiverConfig& config)
    : fd_(fd), config_(config), buffers_(std::make_unique<Buffers>()) {
  const std::size_t slot = config.max_payload_bytes + 1;  // +1 detects truncation via MSG_TRUNC too
  Buffers& b = *buffers_;
  b.payload.resize(config.batch * slot);
  b.control.resize(config.batch * kReceiveControlBytes);
  b.headers.resize(config.batch);
  b.iov.resize(config.batch);
  b.sources.resize(config.batch);
  b.accepted.resize(config.batch);
}

UdpReceiver::UdpReceiver(UdpReceiver&& other) noexcept
    : fd_(other.fd_),
      config_(other.config_),
      buffers_(std::move(other.buffers_)),
      ready_(other.ready_),
      bound_port_(other.bound_port_),
      last_overflow_count_(other.last_overflow_count_),
      stats_(other.stats_) {
  other.fd_ = -1;
}

UdpReceiver::~UdpReceiver() {
  if (fd_ >= 0) ::close(fd_);
}

const ReceivedDatagram& UdpReceiver::datagram(std::size_t i) const {
  MSGRAPHS_ASSERT(i < ready_, "UdpReceiver::datagram index beyond the batch");
  return buffers_->accepted[i];
}

std::size_t UdpReceiver::ReceiveBatch(int& error_out) {
  Buffers& b = *buffers_;
  const std::size_t slot = config_.max_payload_bytes + 1;
  for (std::size_t i = 0; i < config_.batch; ++i) {
    b.iov[i] = {b.payload.data() + i * slot, slot};
    msghdr& h = b.headers[i].msg_hdr;
    h = msghdr{};
    h.msg_name = &b.sources[i];
    h.msg_namelen = sizeof(sockaddr_in);
    h.msg_iov = &b.iov[i];
    h.msg_iovlen = 1;
    h.msg_control = b.control.data() + i * kReceiveControlBytes;
    h.msg_controllen = kReceiveControlBytes;
    b.headers[i].msg_len = 0;
  }
  ++stats_.receive_calls;
  const int n = ::recvmmsg(fd_, b.headers.data(), static_cast<unsigned>(config_.batch), MSG_DONTWAIT,
                           nullptr);
  if (n < 0) {
    error_out = errno;
    return 0;
  }
  error_out = 0;
  const UnixTime now = stats_.kernel_timestamps ? UnixTime() : UnixNow();
  std::size_t accepted = 0;
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const msghdr& h = b.headers[k].msg_hdr;
    const ReceiveMetadata meta = ParseReceiveMetadata(h);
    AccumulateDrops(meta, last_overflow_count_, stats_.kernel_drops);
    const std::size_t length = b.headers[k].msg_len;
    if ((h.msg_flags & MSG_TRUNC) != 0 || length > config_.max_payload_bytes) {
      ++stats_.truncated;
      continue;
    }
    const sockaddr_in& from = b.sources[k];
    const std::uint32_t source_address = ntohl(from.sin_addr.s_addr);
    if ((config_.expected_source != 0 && source_address != config_.expected_source) ||
        (config_.expected_payload_bytes != 0 && length != config_.expected_payload_bytes)) {
      ++stats_.foreign;
      continue;
    }
    ReceivedDatagram& d = b.accepted[accepted++];
    d.kernel_time = stats_.kernel_timestamps && meta.has_time ? meta.time : now;
    d.source = {source_address, ntohs(from.sin_port)};
    d.payload = {b.payload.data() + k * slot, length};
    ++stats_.datagrams;
    stats_.bytes += length;
  }
  if (static_cast<std::size_t>(n) > stats_.peak_batch) stats_.peak_batch = static_cast<std::size_t>(n);
  return accepted;
}

Expected<std::size_t> UdpReceiver::Receive(SteadyTime deadline) {
  ready_ = 0;
  for (;;) {
    int error = 0;
    const std::size_t accepted = ReceiveBatch(error);
    if (accepted > 0) {
      ready_ = accepted;
      return accepted;
    }
    if (error != 0 && error != EAGAIN && error != EWOULDBLOCK && error != EINTR) {
      return Error{Errc::kIo, "udp: recvmmsg failed", error};
    }
    if (error == 0) continue;  // a batch of only rejected datagrams: look again at once
    if (SteadyNow() >= deadline) return std::size_t{0};
    const int fds[1] = {fd_};
    auto ready = WaitReadable(fds, deadline);
    if (!ready) return ready.error();
    if (*ready == 0) return std::size_t{0};
  }
}

Expected<std::uint32_t> WaitReadable(std::span<const int> fds, SteadyTime deadline) {
  if (fds.size() > 32) return Error{Errc::kInvalidArgument, "udp: at most 32 descriptors"};
  pollfd p[32];
  for (std::size_t i = 0; i < fds.size(); ++i) p[i] = pollfd{fds[i], POLLIN, 0};
  for (;;) {
    const timespec timeout = RemainingUntil(deadline);
    const int rc = ::ppoll(p, fds.size(), &timeout, nullptr);
    if (rc < 0) {
      if (errno == EINTR) continue;
      return Error{Errc::kIo, "udp: ppoll failed", errno};
    }
    std::uint32_t mask = 0;
    for (std::size_t i = 0; i < fds.size(); ++i) {
      if ((p[i].revents & (POLLIN | POLLERR)) != 0) mask |= 1u << i;
    }
    return mask;
  }
}

// ---- sender ----------------------------------------------------------------------------------

struct UdpSender::Buffers {
  std::vector<std::uint8_t> payload;
  std::vector<mmsghdr> headers;
  std::vector<iovec> iov;
  std::vector<sockaddr_in> destinations;
};

Status UdpSenderConfig::Validate() const {
  if (batch == 0 || batch > 1024) return Error{Errc::kInvalidConfig, "udp: batch must be 1..1024"};
  if (max_payload_bytes == 0 || max_payload_bytes > 65507) {
    return Error{Errc::kInvalidConfig, "udp: max payload must be 1..65507 bytes"};
  }
  return Ok();
}

Expected<UdpSender> UdpSender::Open(const UdpSenderConfig& config) {
  if (Status s = config.Validate(); !s) return s.error();
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return Error{Errc::kIo, "udp: socket() failed", errno};
  UdpSender sender(fd, config);
  const int one = 1;
  if (config.allow_broadcast && ::setsockopt(fd, SOL_SOCKET, SO_BROADCAST, &one, sizeof(one)) != 0) {
    return Error{Errc::kIo, "udp: SO_BROADCAST failed", errno};
  }
  if (config.send_buffer_bytes > 0) {
    const int want = config.send_buffer_bytes;
    if (::setsockopt(fd, SOL_SOCKET, SO_SNDBUFFORCE, &want, sizeof(want)) != 0) {
      static_cast<void>(::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &want, sizeof(want)));
    }
  }
  const sockaddr_in address = ToSockaddr(config.bind);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    return Error{Errc::kIo, "udp: bind failed", errno};
  }
  return sender;
}

UdpSender::UdpSender(int fd, const UdpSenderConfig& config)
    : fd_(fd), config_(config), buffers_(std::make_unique<Buffers>()) {
  buffers_->payload.resize(config.batch * config.max_payload_bytes);
  buffers_->headers.resize(config.batch);
  buffers_->iov.resize(config.batch);
  buffers_->destinations.resize(config.batch);
}

UdpSender::UdpSender(UdpSender&& other) noexcept
    : fd_(other.fd_),
      config_(other.config_),
      buffers_(std::move(other.buffers_)),
      queued_(other.queued_),
      stats_(other.stats_) {
  other.fd_ = -1;
}

UdpSender::~UdpSender() {
  if (fd_ >= 0) ::close(fd_);
}

Status UdpSender::Send(const Ipv4Endpoint& destination, std::span<const std::uint8_t> payload) {
  const sockaddr_in to = ToSockaddr(destination);
  for (;;) {
    const ssize_t n = ::sendto(fd_, payload.data(), payload.size(), 0,
                               reinterpret_cast<const sockaddr*>(&to), sizeof(to));
    if (n >= 0) break;
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == ENOBUFS) {
      ++stats_.would_block;
      continue;
    }
    ++stats_.errors;
    return Error{Errc::kIo, "udp: sendto failed", errno};
  }
  ++stats_.datagrams;
  stats_.bytes += payload.size();
  return Ok();
}

Status UdpSender::Queue(const Ipv4Endpoint& destination, std::span<const std::uint8_t> payload) {
  if (queued_ == config_.batch) return Error{Errc::kCapacityExceeded, "udp: send queue full"};
  if (payload.size() > config_.max_payload_bytes) {
    return Error{Errc::kInvalidArgument, "udp: payload above max_payload_bytes"};
  }
  Buffers& b = *buffers_;
  std::uint8_t* slot = b.payload.data() + queued_ * config_.max_payload_bytes;
  if (!payload.empty()) std::memcpy(slot, payload.data(), payload.size());
  b.destinations[queued_] = ToSockaddr(destination);
  b.iov[queued_] = {slot, payload.size()};
  msghdr& h = b.headers[queued_].msg_hdr;
  h = msghdr{};
  h.msg_name = &b.destinations[queued_];
  h.msg_namelen = sizeof(sockaddr_in);
  h.msg_iov = &b.iov[queued_];
  h.msg_iovlen = 1;
  ++queued_;
  return Ok();
}

Status UdpSender::SendQueued() {
  std::size_t done = 0;
  while (done < queued_) {
    const int n = ::sendmmsg(fd_, buffers_->headers.data() + done,
                             static_cast<unsigned>(queued_ - done), 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN || errno == ENOBUFS) {
        ++stats_.would_block;
        continue;
      }
      ++stats_.errors;
      queued_ = 0;
      return Error{Errc::kIo, "udp: sendmmsg failed", errno};
    }
    for (int i = 0; i < n; ++i) stats_.bytes += buffers_->iov[done + static_cast<std::size_t>(i)].iov_len;
    stats_.datagrams += static_cast<std::uint64_t>(n);
    done += static_cast<std::size_t>(n);
  }
  queued_ = 0;
  return Ok();
}

}  // namespace msgraphs::platform
