// AtomicFile: write a file so that readers only ever see the old file or the
// complete new one — never a half-written file at the final path.
//
// Parameters
//   path   the final file; the bytes go to `path + ".tmp"` first (created
//          or truncated, mode 0644 before the umask)
//
// commit() flushes the temporary file to disk (fsync), closes it, renames it
// onto `path` (atomic on POSIX file systems) and fsyncs the directory.  If
// commit() is never reached (an exception, an early return) the destructor
// removes the temporary file.  Every failure (unwritable or missing
// directory, disk full, I/O error) throws FileWriteError with the path and
// the system's reason; the file at `path` is then untouched.
//
// Two writers of the same path at the same time share the ".tmp" name; the
// caller serialises writes of one path.
#pragma once
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace skyfarm {

// An image (or any file) could not be written; what() names the path.
class FileWriteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class AtomicFile {
 public:
  // Opens path + ".tmp" for writing; throws FileWriteError if it cannot.
  explicit AtomicFile(std::filesystem::path path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::filesystem::path& path() const { return path_; }
  const std::filesystem::path& temporary_path() const { return tmp_; }

  // Writes n bytes at the current position (all of them, or throws).
  void write(const void* data, std::size_t n);
  std::uint64_t tell() const { return pos_; }
  void seek(std::uint64_t pos);

  // fsync, close, rename onto path(); throws FileWriteError on failure (the
  // temporary file is then removed).
  // kRenamed skips both fsyncs: still atomic for readers, but after a power
  // failure the file may be the old one or empty; for data that can be
  // recomputed and is validated when read (the farm's merged tiles).
  enum class Durability { kSynced, kRenamed };
  void commit(Durability durability = Durability::kSynced);

  // Writes a whole buffer to `path` atomically.
  static void write_file(const std::filesystem::path& path, const void* data, std::size_t n);

 private:
  [[noreturn]] void fail(const std::string& what, int err);
  void discard() noexcept;

  std::filesystem::path path_, tmp_;
  int fd_ = -1;
  std::uint64_t pos_ = 0;
  bool committed_ = false;
};

}  // namespace skyfarm
