// SPDX-License-Identifier: MIT
#include "msgraphs/drivers/velodyne/scan_assembler.hpp"

#include <utility>

namespace msgraphs::drivers::velodyne {
namespace {

std::uint32_t Forward(std::uint32_t from, std::uint32_t to) {
  return (to + kAzimuthUnitsPerTurn - from) % kAzimuthUnitsPerTurn;
}
constexpr std::uint32_t kHalfTurn = kAzimuthUnitsPerTurn / 2;

}  // namespace

Status ScanAssemblerConfig::Validate() const {
  if (cut_azimuth_cdeg >= kAzimuthUnitsPerTurn) {
    return Error{Errc::kInvalidConfig, "scan assembler: cut azimuth must be below 36000"};
  }
  if (capacity_points == 0 || capacity_points > (1u << 24)) {
    return Error{Errc::kInvalidConfig, "scan assembler: capacity must be 1..16M points"};
  }
  if (max_scan_duration <= Duration() || max_scan_duration > Duration::FromSeconds(4.0)) {
    return Error{Errc::kInvalidConfig, "scan assembler: max scan duration must be in (0, 4] s"};
  }
  return Ok();
}

Expected<ScanAssembler> ScanAssembler::Create(const ScanAssemblerConfig& config) {
  if (Status s = config.Validate(); !s) return s.error();
  return ScanAssembler(config);
}

ScanAssembler::ScanAssembler(const ScanAssemblerConfig& config) : config_(config) {
  buffers_[0].points.Init(config.capacity_points);
  buffers_[1].points.Init(config.capacity_points);
}

ScanAssembler::ScanAssembler(ScanAssembler&& other) noexcept { *this = std::move(other); }
ScanAssembler& ScanAssembler::operator=(ScanAssembler&& other) noexcept {
  config_ = other.config_;
  const bool current_is_0 = other.current_ == &other.buffers_[0];
  buffers_[0] = std::move(other.buffers_[0]);
  buffers_[1] = std::move(other.buffers_[1]);
  current_ = current_is_0 ? &buffers_[0] : &buffers_[1];
  completed_ = current_is_0 ? &buffers_[1] : &buffers_[0];
  current_started_at_cut_ = other.current_started_at_cut_;
  have_last_azimuth_ = other.have_last_azimuth_;
  last_azimuth_cdeg_ = other.last_azimuth_cdeg_;
  next_sequence_ = other.next_sequence_;
  stats_ = other.stats_;
  return *this;
}
ScanAssembler::~ScanAssembler() = default;

void ScanAssembler::Append(Scan& scan, UnixTime first_firing, const VelodynePoint& point) {
  VelodynePoint rebased = point;
  const std::int64_t offset_ns =
      (first_firing - scan.start_time).nanoseconds() + static_cast<std::int64_t>(point.time_offset_ns);
  rebased.time_offset_ns = static_cast<std::uint32_t>(offset_ns);
  if (!scan.points.try_push_back(rebased)) {
    ++scan.dropped_points;
    ++stats_.dropped_points;
    return;
  }
  const UnixTime t = scan.start_time + Duration::FromNanoseconds(offset_ns);
  if (t > scan.end_time) scan.end_time = t;
}

void ScanAssembler::Deliver(bool ends_at_cut) {
  Scan& done = *current_;
  done.complete = ends_at_cut && current_started_at_cut_;
  done.sequence = next_sequence_++;
  if (done.points.size() > stats_.peak_points) stats_.peak_points = done.points.size();
  ++stats_.scans;
  if (!done.complete) ++stats_.partial_scans;
  std::swap(current_, completed_);
  current_->points.clear();
  current_->packets = 0;
  current_->dropped_points = 0;
  current_->complete = false;
  current_->start_time = UnixTime();
  current_->end_time = UnixTime();
  current_started_at_cut_ = ends_at_cut;
}

void ScanAssembler::BeginPacket(Scan& scan, UnixTime first_firing) {
  if (scan.packets == 0) {
    scan.start_time = first_firing;
    scan.end_time = first_firing;
  }
  ++scan.packets;
}

bool ScanAssembler::Flush() {
  if (current_->packets == 0) return false;
  Deliver(false);
  return true;
}

bool ScanAssembler::AddPacket(UnixTime first_firing, const DecodedPacket& packet,
                              std::span<const VelodynePoint> points) {
  ++stats_.packets;
  bool delivered = false;

  // An input gap or a stalled sensor: close the scan rather than let it span rotations.
  if (current_->packets > 0 &&
      first_firing - current_->start_time > config_.max_scan_duration) {
    ++stats_.timeouts;
    Deliver(false);
    delivered = true;
  }
  if (current_->packets > 0 && first_firing < current_->start_time) {
    ++stats_.time_regressions;
    stats_.dropped_regressed_points += points.size();
    return delivered;
  }

  // The packet covers azimuths [start_az, end_az): from where the previous packet ended.
  const std::uint32_t start_az = have_last_azimuth_ ? last_azimuth_cdeg_ : packet.first_azimuth_cdeg;
  const std::uint32_t span = Forward(start_az, packet.end_azimuth_cdeg);
  const std::uint32_t to_cut = Forward(start_az, config_.cut_azimuth_cdeg);
  const bool crosses = span < kHalfTurn && to_cut > 0 && to_cut <= span;
  have_last_azimuth_ = true;
  last_azimuth_cdeg_ = packet.end_azimuth_cdeg;

  if (!crosses) {
    BeginPacket(*current_, first_firing);
    for (const VelodynePoint& p : points) Append(*current_, first_firing, p);
    return delivered;
  }

  // The cut lies inside this packet: points before it (by azimuth, so both returns of a dual
  // firing go the same way) close the current scan, the rest open the next one.
  BeginPacket(*current_, first_firing);
  for (const VelodynePoint& p : points) {
    const std::uint32_t d = Forward(start_az, p.azimuth_cdeg);
    if (d < to_cut || d >= kHalfTurn) Append(*current_, first_firing, p);
  }
  // A scan that never received data (start-up exactly at the cut) is not worth delivering.
  const bool has_data = !current_->points.empty() || current_->dropped_points > 0;
  if (has_data) {
    Deliver(true);
    delivered = true;
  } else {
    current_->packets = 0;
    current_started_at_cut_ = true;
  }
  BeginPacket(*current_, first_firing);
  for (const VelodynePoint& p : points) {
    const std::uint32_t d = Forward(start_az, p.azimuth_cdeg);
    if (d >= to_cut && d < kHalfTurn) Append(*current_, first_firing, p);
  }
  return delivered;
}

}  // namespace msgraphs::drivers::velodyne
