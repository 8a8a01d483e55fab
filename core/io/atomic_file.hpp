// AtomicFile: write a file so that a reader sees either the old file or the
// complete new one, never a half-written one.
//
// The content goes to a temporary file in the target's own directory (same file
// system, so rename(2) is atomic). commit() flushes it to disk and renames it
// over the target. If commit() is never reached (an exception, an early
// return), the destructor removes the temporary file, so a failure leaves
// nothing behind.
//
// Write through temp_path() (e.g. hand it to a library that opens files by
// name) or use write_file_atomically() for a string. POSIX only.
#pragma once

#include <string>
#include <string_view>

namespace codyna {

class AtomicFile {
 public:
  // Creates the temporary file (mode 0666 minus the umask, like a plain
  // open()). Throws std::runtime_error naming `target` and the reason (e.g. the
  // directory does not exist or is not writable).
  explicit AtomicFile(std::string target);
  ~AtomicFile();  // removes the temporary file unless committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& target() const { return target_; }
  const std::string& temp_path() const { return temp_; }

  // fsync the temporary file, rename it to target, fsync the directory.
  // Throws std::runtime_error naming target and the reason; the temporary file
  // is then removed by the destructor.
  void commit();

 private:
  std::string target_, temp_;
  bool committed_ = false;
  int slot_ = -1;  // in the table remove_temporary_files() reads
};

// Removes the temporary files of every AtomicFile still being written. Async-signal-safe
// (unlink only): a front end's SIGINT/SIGTERM handler calls it before the process ends, so
// an interrupted write leaves nothing behind. (After kill -9, the next write of the same
// target removes the leftovers of writers that no longer run.)
void remove_temporary_files();

// Writes `content` to `path` through an AtomicFile.
void write_file_atomically(const std::string& path, std::string_view content);

}  // namespace codyna
