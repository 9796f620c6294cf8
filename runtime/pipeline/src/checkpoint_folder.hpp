// SPDX-License-Identifier: MIT
// The checkpoint folder's files (checkpoint.hpp): names, listing, reading, syncing, setting
// aside. POSIX calls where durability needs them (fsync of a file and of its folder).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "msgraphs/base/expected.hpp"

namespace msgraphs::runtime {

/// journal.bin (generation 0), journal.N.bin, snapshot.N.bin in `dir`.
std::string CheckpointPath(const std::string& dir, bool snapshot, std::uint64_t generation);

struct CheckpointFolder {
  std::vector<std::uint64_t> snapshots, journals;  ///< generations present, ascending
  std::vector<std::string> not_regular;  ///< entries with those names that are not regular files
};
/// The generations in `dir` (regular files only); leftover snapshot.N.tmp files (a write cut
/// short) are removed.
Expected<CheckpointFolder> ListCheckpointFolder(const std::string& dir);

/// Reads `path` whole into `out` (resized); kCapacityExceeded beyond `max_bytes`, kIo when it
/// cannot be read. A link is not followed.
Status ReadWholeFile(const std::string& path, std::size_t max_bytes, std::vector<std::uint8_t>& out);

/// Writes `parts`, one after the other, to `path` durably: to name.tmp, fsync, rename, fsync of
/// the folder.
Status WriteFileDurably(const std::string& dir, const std::string& path,
                        std::span<const std::span<const std::uint8_t>> parts);

/// fdatasync of a file (opened for reading, not following links).
Status SyncFile(const std::string& path);

/// fsync of the folder itself: a file created, renamed or removed in it survives a power cut.
Status SyncFolder(const std::string& dir);

/// Renames `path` to path.dropped (or .dropped.2, .3, ... when taken): kept for a look, never
/// read again. Returns the new name (empty when the rename failed).
std::string SetAside(const std::string& path);

}  // namespace msgraphs::runtime
