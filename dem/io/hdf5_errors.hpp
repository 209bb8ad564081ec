#pragma once
// HDF5 failures turned into one-line reasons for OutputError messages, instead of HDF5's own
// error-stack printout on stderr.
#include <hdf5.h>

#include <string>

namespace grainflow {

// Silences HDF5's automatic error printing while in scope; the previous handler comes back
// afterwards, so other HDF5 users are unaffected.
class QuietHdf5Errors {
 public:
  QuietHdf5Errors() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5Errors() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  QuietHdf5Errors(const QuietHdf5Errors&) = delete;
  QuietHdf5Errors& operator=(const QuietHdf5Errors&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

// The current HDF5 error stack in one line, then clears it: the most specific cause (deepest
// entry, e.g. the OS or MPI-IO error) and the API call it surfaced in. When the cause carries
// an operating-system error number (HDF5's POSIX driver writes "errno = 28, ..."), that
// error's text replaces it, e.g. "No space left on device".
std::string hdf5_reason();

}  // namespace grainflow
