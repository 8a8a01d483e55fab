// HDF5 as codyna uses it (results files, and MAT v7.3 through libmatio).
//
// QuietHdf5: while one lives, HDF5 prints nothing on its own (codyna reports
// failures itself, naming the file). Linking this unit also tells HDF5 not to
// install its atexit cleanup: after a failed flush (a full disk), that cleanup
// tries to flush the same file again and crashes the process after codyna has
// already reported the error and kept the old file.
#pragma once

namespace codyna {

class QuietHdf5 {
 public:
  QuietHdf5();
  ~QuietHdf5();
  QuietHdf5(const QuietHdf5&) = delete;
  QuietHdf5& operator=(const QuietHdf5&) = delete;

 private:
  void* func_ = nullptr;
  void* data_ = nullptr;
};

}  // namespace codyna
