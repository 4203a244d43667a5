#include "common/image/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace skyfarm {

namespace {

std::string errno_text(int err) { return std::strerror(err); }

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path path) : path_(std::move(path)) {
  tmp_ = path_;
  tmp_ += ".tmp";
  do {
    fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  } while (fd_ < 0 && errno == EINTR);
  if (fd_ < 0) {
    const int err = errno;
    throw FileWriteError("cannot write '" + path_.string() + "': cannot create '" + tmp_.string() +
                         "': " + errno_text(err));
  }
}

AtomicFile::~AtomicFile() {
  if (!committed_) discard();
}

void AtomicFile::discard() noexcept {
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  ::unlink(tmp_.c_str());
}

void AtomicFile::fail(const std::string& what, int err) {
  discard();
  committed_ = true;  // nothing left to clean up
  throw FileWriteError("cannot write '" + path_.string() + "': " + what + ": " + errno_text(err));
}

void AtomicFile::write(const void* data, std::size_t n) {
  if (fd_ < 0) throw FileWriteError("cannot write '" + path_.string() + "': the file is already closed");
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t k = ::write(fd_, p, n);
    if (k < 0) {
      const int err = errno;
      if (err == EINTR) continue;
      fail("write to '" + tmp_.string() + "' failed", err);
    }
    if (k == 0) fail("write to '" + tmp_.string() + "' made no progress", EIO);
    p += k;
    n -= static_cast<std::size_t>(k);
    pos_ += static_cast<std::uint64_t>(k);
  }
}

void AtomicFile::seek(std::uint64_t pos) {
  if (fd_ < 0) throw FileWriteError("cannot write '" + path_.string() + "': the file is already closed");
  if (::lseek(fd_, static_cast<off_t>(pos), SEEK_SET) < 0) {
    const int err = errno;
    fail("seek in '" + tmp_.string() + "' failed", err);
  }
  pos_ = pos;
}

void AtomicFile::commit(Durability durability) {
  if (fd_ < 0) throw FileWriteError("cannot write '" + path_.string() + "': the file is already closed");
  const bool sync = durability == Durability::kSynced;
  if (sync && ::fsync(fd_) != 0) {
    const int err = errno;  // EINVAL/EROFS: a file system without fsync (not an error)
    if (err != EINVAL && err != EROFS) fail("fsync of '" + tmp_.string() + "' failed", err);
  }
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) {
    const int err = errno;
    if (err != EINTR) fail("close of '" + tmp_.string() + "' failed", err);
  }
  if (::rename(tmp_.c_str(), path_.c_str()) != 0) {
    const int err = errno;
    fail("cannot rename '" + tmp_.string() + "' onto it", err);
  }
  committed_ = true;
  if (!sync) return;
  // Make the rename itself durable (best effort: some file systems refuse).
  std::filesystem::path dir = path_.parent_path();
  if (dir.empty()) dir = ".";
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
}

void AtomicFile::write_file(const std::filesystem::path& path, const void* data, std::size_t n) {
  AtomicFile f(path);
  f.write(data, n);
  f.commit();
}

}  // namespace skyfarm
