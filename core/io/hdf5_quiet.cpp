#include "io/hdf5_quiet.hpp"

#include <hdf5.h>

namespace codyna {

namespace {
// before main(), so before HDF5 initializes: no library cleanup at exit
const bool g_no_atexit = (H5dont_atexit(), true);
}  // namespace

QuietHdf5::QuietHdf5() {
  (void)g_no_atexit;
  H5E_auto2_t f = nullptr;
  H5Eget_auto2(H5E_DEFAULT, &f, &data_);
  func_ = reinterpret_cast<void*>(f);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

QuietHdf5::~QuietHdf5() { H5Eset_auto2(H5E_DEFAULT, reinterpret_cast<H5E_auto2_t>(func_), data_); }

}  // namespace codyna
