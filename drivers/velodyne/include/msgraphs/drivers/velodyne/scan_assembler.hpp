// SPDX-License-Identifier: MIT
// Cuts the stream of decoded packets into rotations (scans) at a configurable azimuth.
//
// Capacity and overflow: each scan holds at most `capacity_points` points (two buffers are
// allocated at Create, nothing after). Points beyond capacity are dropped, counted in the
// scan's `dropped_points` and in stats(); the scan is still delivered, never silently cut.
// Per-point time is re-based to the scan start so that deskewing needs only the scan.
#pragma once

#include <cstdint>
#include <span>

#include "msgraphs/base/bounded_vector.hpp"
#include "msgraphs/base/expected.hpp"
#include "msgraphs/base/time.hpp"
#include "msgraphs/drivers/velodyne/data_packet_decoder.hpp"
#include "msgraphs/drivers/velodyne/point.hpp"

namespace msgraphs::drivers::velodyne {

struct ScanAssemblerConfig {
  std::uint16_t cut_azimuth_cdeg = 0;  ///< scans start at this azimuth (0.01 degree units)
  /// VLP-16 at 300 RPM, dual return: 16 lasers x 2 x 1800 firings = 57,600 returns per turn.
  std::size_t capacity_points = 65536;
  /// A scan whose data spans longer than this (sensor stopped, input gap) is delivered as
  /// incomplete instead of growing into the next rotation. 5 Hz is the slowest VLP-16 rate.
  Duration max_scan_duration = Duration::FromMilliseconds(250);

  Status Validate() const;
};

struct Scan {
  std::uint64_t sequence = 0;  ///< counts delivered scans from 0
  UnixTime start_time;         ///< time base of the points' time_offset_ns
  UnixTime end_time;           ///< time of the latest firing in the scan
  /// Points, in arrival order; time_offset_ns is relative to start_time.
  BoundedVector<VelodynePoint> points;
  std::uint32_t packets = 0;
  std::uint32_t dropped_points = 0;  ///< overflow: capacity reached
  /// True when the scan began and ended at the cut azimuth (a whole rotation). The first scan
  /// after start-up and scans closed by a timeout or Flush are partial.
  bool complete = false;
};

struct ScanAssemblerStats {
  std::uint64_t packets = 0;
  std::uint64_t scans = 0;
  std::uint64_t partial_scans = 0;
  std::uint64_t dropped_points = 0;      ///< overflow
  std::uint64_t time_regressions = 0;    ///< packets older than their scan's start, dropped
  std::uint64_t dropped_regressed_points = 0;
  std::uint64_t timeouts = 0;            ///< scans closed by max_scan_duration
  std::size_t peak_points = 0;
};

class ScanAssembler {
 public:
  static Expected<ScanAssembler> Create(const ScanAssemblerConfig& config);

  /// Adds one decoded packet whose first firing happened at `first_firing`. Returns true when
  /// this completed a scan; it is then in completed() until the next call that returns true.
  bool AddPacket(UnixTime first_firing, const DecodedPacket& packet,
                 std::span<const VelodynePoint> points);

  /// Delivers the scan in progress (if it has points) as a partial scan.
  bool Flush();

  const Scan& completed() const { return *completed_; }
  const ScanAssemblerStats& stats() const { return stats_; }
  const ScanAssemblerConfig& config() const { return config_; }

  ScanAssembler(ScanAssembler&&) noexcept;
  ScanAssembler& operator=(ScanAssembler&&) noexcept;
  ~ScanAssembler();

 private:
  explicit ScanAssembler(const ScanAssemblerConfig& config);
  static void BeginPacket(Scan& scan, UnixTime first_firing);
  void Append(Scan& scan, UnixTime first_firing, const VelodynePoint& point);
  void Deliver(bool ends_at_cut);

  ScanAssemblerConfig config_;
  Scan buffers_[2];
  Scan* current_ = &buffers_[0];
  Scan* completed_ = &buffers_[1];
  bool current_started_at_cut_ = false;
  bool have_last_azimuth_ = false;
  std::uint16_t last_azimuth_cdeg_ = 0;
  std::uint64_t next_sequence_ = 0;
  ScanAssemblerStats stats_;
};

}  // namespace msgraphs::drivers::velodyne
