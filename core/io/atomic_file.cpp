#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

namespace codyna {
namespace {

std::runtime_error os_error(const std::string& target, const std::string& what, int err) {
  return std::runtime_error(target + ": " + what + ": " + std::strerror(err));
}

// The process umask without changing it (umask(2) can only be read by setting
// it, which races with other threads); Linux reports it in /proc.
mode_t current_umask() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "Umask:") {
      std::string octal;
      status >> octal;
      return static_cast<mode_t>(std::stoul(octal, nullptr, 8));
    }
  }
  return 022;
}

// Temporary files being written, for remove_temporary_files() (signal handlers):
// fixed slots, so the handler needs neither locks nor allocation.
constexpr int kSlots = 16;
constexpr int kPathMax = 4096;
char g_temp[kSlots][kPathMax];
std::atomic<bool> g_used[kSlots];

int register_temp(const std::string& path) {
  if (path.size() >= kPathMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (g_used[i].compare_exchange_strong(expected, true)) {
      std::memcpy(g_temp[i], path.c_str(), path.size() + 1);
      return i;
    }
  }
  return -1;
}

void unregister_temp(int slot) {
  if (slot >= 0) g_used[slot].store(false);
}

// ".NAME.tmp-PID-XXXXXX" files of the same target left by a process that no longer
// runs (killed while writing) are removed before a new write.
void remove_stale_temporaries(const std::string& dir, const std::string& name) {
  const std::string prefix = "." + name + ".tmp-";
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string f = entry.path().filename().string();
    if (f.rfind(prefix, 0) != 0) continue;
    const std::string rest = f.substr(prefix.size());
    const auto dash = rest.find('-');
    if (dash == std::string::npos || dash == 0) continue;  // not ours (older files have no pid)
    char* end = nullptr;
    const long pid = std::strtol(rest.c_str(), &end, 10);
    if (end != rest.c_str() + dash || pid <= 0) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // its writer still runs
    std::filesystem::remove(entry.path(), ec);
  }
}

std::string parent_dir(const std::string& path) {
  auto dir = std::filesystem::path(path).parent_path();
  return dir.empty() ? std::string(".") : dir.string();
}

// 0 on success, else the errno of the failing call
int fsync_path(const std::string& path, int flags) {
  int fd = ::open(path.c_str(), flags);
  if (fd < 0) return errno;
  int err = ::fsync(fd) == 0 ? 0 : errno;
  ::close(fd);
  return err;
}

}  // namespace

AtomicFile::AtomicFile(std::string target) : target_(std::move(target)) {
  const auto name = std::filesystem::path(target_).filename().string();
  if (name.empty()) throw std::runtime_error(target_ + ": not a file name");
  // fail now rather than at the rename, after other files may have been committed
  std::error_code ec;
  if (std::filesystem::is_directory(target_, ec)) throw std::runtime_error(target_ + ": is a directory");
  remove_stale_temporaries(parent_dir(target_), name);
  std::string pattern = parent_dir(target_) + "/." + name + ".tmp-" + std::to_string(::getpid()) + "-XXXXXX";
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  int fd = ::mkstemp(buf.data());
  if (fd < 0) throw os_error(target_, "cannot create a temporary file in " + parent_dir(target_), errno);
  temp_ = buf.data();
  slot_ = register_temp(temp_);
  // mkstemp makes the file private (0600); give it the mode a plain open() would.
  int rc = ::fchmod(fd, 0666 & ~current_umask());
  int err = errno;
  ::close(fd);
  if (rc != 0) {
    std::remove(temp_.c_str());
    unregister_temp(slot_);
    slot_ = -1;
    throw os_error(target_, "cannot set the mode of " + temp_, err);
  }
}

AtomicFile::~AtomicFile() {
  if (!committed_) std::remove(temp_.c_str());
  unregister_temp(slot_);
}

void remove_temporary_files() {
  for (int i = 0; i < kSlots; ++i)
    if (g_used[i].load()) ::unlink(g_temp[i]);
}

void AtomicFile::commit() {
  if (int err = fsync_path(temp_, O_RDONLY)) throw os_error(target_, "cannot flush " + temp_, err);
  if (std::rename(temp_.c_str(), target_.c_str()) != 0)
    throw os_error(target_, "cannot rename " + temp_ + " to it", errno);
  committed_ = true;
  // make the rename itself durable; the file is complete either way
  fsync_path(parent_dir(target_), O_RDONLY | O_DIRECTORY);
}

void write_file_atomically(const std::string& path, std::string_view content) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path(), std::ios::binary | std::ios::trunc);
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.close();
    if (!out) throw std::runtime_error(path + ": cannot write " + file.temp_path());
  }
  file.commit();
}

}  // namespace codyna
