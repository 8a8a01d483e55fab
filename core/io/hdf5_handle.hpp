// The HDF5 plumbing shared by the files codyna writes with the HDF5 C API (io/results_file.cpp,
// study/sweep.cpp): an identifier closed on destruction, and failures turned into Hdf5Error with
// the most specific message on HDF5's error stack (the callers prefix the path). Use under a
// QuietHdf5 (io/hdf5_quiet.hpp), so that HDF5 prints nothing itself.
#pragma once

#include <hdf5.h>

#include <stdexcept>
#include <string>
#include <utility>

namespace codyna {

// A failure inside an HDF5 file; the public functions of the writers prefix the path.
class Hdf5Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The most specific message on HDF5's error stack.
inline std::string hdf5_reason() {
  std::string reason;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned n, const H5E_error2_t* e, void* out) -> herr_t {
        if (n == 0 && e->desc) *static_cast<std::string*>(out) = e->desc;
        return 0;
      },
      &reason);
  // a failed system call: HDF5's text carries a time stamp, the file descriptor, buffer
  // addresses, ... and the one thing a user needs, the system's message
  const std::string key = "error message = '";
  if (const auto a = reason.find(key); a != std::string::npos)
    if (const auto b = reason.find('\'', a + key.size()); b != std::string::npos)
      return reason.substr(a + key.size(), b - a - key.size());
  return reason.empty() ? "HDF5 error" : reason;
}

[[noreturn]] inline void hdf5_fail(const std::string& what) { throw Hdf5Error(what + ": " + hdf5_reason()); }

inline void hdf5_check(herr_t rc, const std::string& what) {
  if (rc < 0) hdf5_fail(what);
}

// An HDF5 identifier closed on destruction; a negative id (a failed call) throws.
class Hdf5Handle {
 public:
  using Close = herr_t (*)(hid_t);
  Hdf5Handle(hid_t id, Close close, const std::string& what) : id_(id), close_(close) {
    if (id_ < 0) hdf5_fail(what);
  }
  Hdf5Handle(Hdf5Handle&& other) noexcept : id_(std::exchange(other.id_, -1)), close_(other.close_) {}
  Hdf5Handle(const Hdf5Handle&) = delete;
  Hdf5Handle& operator=(const Hdf5Handle&) = delete;
  Hdf5Handle& operator=(Hdf5Handle&&) = delete;
  ~Hdf5Handle() {
    if (id_ >= 0) close_(id_);
  }
  operator hid_t() const { return id_; }

  // Close now and report a failure (closing a file flushes it).
  void close(const std::string& what) { hdf5_check(close_(std::exchange(id_, -1)), what); }

 private:
  hid_t id_;
  Close close_;
};

}  // namespace codyna
