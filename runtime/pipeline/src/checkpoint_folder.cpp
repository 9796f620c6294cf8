// SPDX-License-Identifier: MIT
#include "checkpoint_folder.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>

#include "msgraphs/runtime/pipeline/checkpoint_file.hpp"

namespace msgraphs::runtime {

namespace {

Status IoError(const char* what) { return Error{Errc::kIo, what, errno}; }

// A file descriptor closed on every path out.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }
  int Release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

 private:
  int fd_;
};

bool Exists(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0;
}

}  // namespace

std::string CheckpointPath(const std::string& dir, bool snapshot, std::uint64_t generation) {
  if (!snapshot && generation == 0) return dir + "/journal.bin";
  return dir + (snapshot ? "/snapshot." : "/journal.") + std::to_string(generation) + ".bin";
}

Expected<CheckpointFolder> ListCheckpointFolder(const std::string& dir) {
  DIR* d = ::opendir(dir.c_str());
  if (d == nullptr) return IoError("checkpoint: cannot open the folder").error();
  CheckpointFolder out;
  std::vector<std::string> leftovers;
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    bool snapshot = false;
    std::uint64_t generation = 0;
    if (CheckpointGeneration(name, snapshot, generation)) {
      struct stat st {};
      const std::string path = dir + "/" + name;
      if (::lstat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
        out.not_regular.push_back(path);
        continue;
      }
      (snapshot ? out.snapshots : out.journals).push_back(generation);
    } else if (name.rfind("snapshot.", 0) == 0 && name.size() > 4 &&
               name.compare(name.size() - 4, 4, ".tmp") == 0) {
      leftovers.push_back(dir + "/" + name);
    }
  }
  ::closedir(d);
  for (const std::string& path : leftovers) ::unlink(path.c_str());
  std::sort(out.snapshots.begin(), out.snapshots.end());
  std::sort(out.journals.begin(), out.journals.end());
  return out;
}

Status ReadWholeFile(const std::string& path, std::size_t max_bytes, std::vector<std::uint8_t>& out) {
  // O_NONBLOCK: a FIFO under the name must not block the start (it is refused below).
  Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK));
  if (fd.get() < 0) return IoError("cannot open the file (or it is a link)");
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) return IoError("cannot stat the file");
  if (!S_ISREG(st.st_mode)) return Error{Errc::kInvalidArgument, "not a regular file"};
  if (static_cast<std::uint64_t>(st.st_size) > max_bytes)
    return Error{Errc::kCapacityExceeded, "larger than any snapshot of this config"};
  out.resize(static_cast<std::size_t>(st.st_size));
  std::size_t done = 0;
  while (done < out.size()) {
    const ssize_t n = ::read(fd.get(), out.data() + done, out.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return IoError("cannot read the file");
    done += static_cast<std::size_t>(n);
  }
  return Ok();
}

Status WriteFileDurably(const std::string& dir, const std::string& path,
                        std::span<const std::span<const std::uint8_t>> parts) {
  const std::string tmp = path.substr(0, path.size() - 4) + ".tmp";  // name.bin -> name.tmp
  Fd fd(::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644));
  if (fd.get() < 0) return IoError("cannot create the snapshot's temporary file");
  for (const std::span<const std::uint8_t> bytes : parts) {
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(fd.get(), bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const Status e = IoError("cannot write the snapshot (disk full?)");
        ::unlink(tmp.c_str());
        return e;
      }
      done += static_cast<std::size_t>(n);
    }
  }
  if (::fsync(fd.get()) != 0) {
    const Status e = IoError("cannot fsync the snapshot");
    ::unlink(tmp.c_str());
    return e;
  }
  if (::close(fd.Release()) != 0) {
    const Status e = IoError("cannot close the snapshot");
    ::unlink(tmp.c_str());
    return e;
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const Status e = IoError("cannot rename the snapshot into place");
    ::unlink(tmp.c_str());
    return e;
  }
  return SyncFolder(dir);
}

Status SyncFile(const std::string& path) {
  Fd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK));
  if (fd.get() < 0) return IoError("cannot open a journal to sync it");
  if (::fdatasync(fd.get()) != 0) return IoError("cannot fdatasync a journal");
  return Ok();
}

Status SyncFolder(const std::string& dir) {
  Fd fd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (fd.get() < 0) return IoError("cannot open the checkpoint folder to sync it");
  if (::fsync(fd.get()) != 0) return IoError("cannot fsync the checkpoint folder");
  return Ok();
}

std::string SetAside(const std::string& path) {
  std::string to = path + ".dropped";
  for (int i = 2; Exists(to); ++i) {
    if (i >= 1000) return {};  // never over an earlier one
    to = path + ".dropped." + std::to_string(i);
  }
  if (::rename(path.c_str(), to.c_str()) != 0) return {};
  return to;
}

}  // namespace msgraphs::runtime
