#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
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
  std::string pattern = parent_dir(target_) + "/." + name + ".tmp-XXXXXX";
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  int fd = ::mkstemp(buf.data());
  if (fd < 0) throw os_error(target_, "cannot create a temporary file in " + parent_dir(target_), errno);
  temp_ = buf.data();
  // mkstemp makes the file private (0600); give it the mode a plain open() would.
  int rc = ::fchmod(fd, 0666 & ~current_umask());
  int err = errno;
  ::close(fd);
  if (rc != 0) {
    std::remove(temp_.c_str());
    throw os_error(target_, "cannot set the mode of " + temp_, err);
  }
}

AtomicFile::~AtomicFile() {
  if (!committed_) std::remove(temp_.c_str());
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
