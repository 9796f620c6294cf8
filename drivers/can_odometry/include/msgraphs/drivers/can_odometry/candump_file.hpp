// SPDX-License-Identifier: MIT
// candump log files: a streaming reader (one fixed buffer, skips and counts everything that is
// not a classic frame) and a writer.
#pragma once

#include <cstdint>
#include <memory>

#include "msgraphs/base/expected.hpp"
#include "msgraphs/drivers/can_odometry/candump.hpp"

namespace msgraphs::drivers::can_odometry {

struct CandumpReadStats {
  std::uint64_t lines = 0;
  std::uint64_t frames = 0;     ///< classic frames delivered
  std::uint64_t comments = 0;   ///< blank and comment lines
  std::uint64_t can_fd = 0;     ///< CAN FD frames skipped
  std::uint64_t can_xl = 0;     ///< CAN XL frames skipped
  std::uint64_t malformed = 0;  ///< broken or over-long lines skipped
};

class CandumpFileReader {
 public:
  static Expected<CandumpFileReader> Open(const char* path);

  /// true: `line` holds the next classic frame; false: end of file. Errors only for I/O.
  Expected<bool> Next(CandumpLine& line);
  const CandumpReadStats& stats() const { return stats_; }
  /// The reason the most recent malformed line was skipped ("" if none).
  const char* last_malformed_reason() const { return last_reason_; }
  std::uint64_t last_malformed_line() const { return last_malformed_line_; }

  CandumpFileReader(CandumpFileReader&& other) noexcept;
  CandumpFileReader& operator=(CandumpFileReader&&) = delete;
  ~CandumpFileReader();

 private:
  explicit CandumpFileReader(int fd);
  Expected<bool> ReadLine(std::string_view& line);

  int fd_ = -1;
  std::unique_ptr<char[]> buffer_;
  std::size_t begin_ = 0;
  std::size_t end_ = 0;
  bool eof_ = false;
  CandumpReadStats stats_;
  const char* last_reason_ = "";
  std::uint64_t last_malformed_line_ = 0;
};

class CandumpFileWriter {
 public:
  static Expected<CandumpFileWriter> Create(const char* path, CandumpPrecision precision);
  Status Write(UnixTime stamp, std::string_view interface, const CanFrame& frame);
  Status Close();
  std::uint64_t frames() const { return frames_; }

  CandumpFileWriter(CandumpFileWriter&& other) noexcept;
  CandumpFileWriter& operator=(CandumpFileWriter&&) = delete;
  ~CandumpFileWriter();

 private:
  CandumpFileWriter(int fd, CandumpPrecision precision);
  Status Flush();
  int fd_ = -1;
  CandumpPrecision precision_;
  std::unique_ptr<char[]> buffer_;
  std::size_t used_ = 0;
  std::uint64_t frames_ = 0;
};

}  // namespace msgraphs::drivers::can_odometry
