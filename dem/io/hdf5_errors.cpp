#include "dem/io/hdf5_errors.hpp"

#include <cstdlib>
#include <cstring>
#include <vector>

namespace grainflow {
namespace {

struct ErrorRecord {
  std::string function;
  std::string description;
};

herr_t collect_error(unsigned /*n*/, const H5E_error2_t* err, void* out) {
  static_cast<std::vector<ErrorRecord>*>(out)->push_back(
      {err->func_name ? err->func_name : "?", err->desc ? err->desc : ""});
  return 0;
}

// "... errno = 28, error message = '...' ..." (H5FDsec2.c) -> 28; 0 when absent.
int errno_in(const std::string& description) {
  const std::size_t at = description.find("errno = ");
  return at == std::string::npos ? 0 : std::atoi(description.c_str() + at + 8);
}

}  // namespace

std::string hdf5_reason() {
  std::vector<ErrorRecord> stack;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, collect_error, &stack);
  H5Eclear2(H5E_DEFAULT);
  if (stack.empty()) return "HDF5 reported no reason";
  const ErrorRecord& cause = stack.front();
  const ErrorRecord& api = stack.back();
  std::string out = cause.description;
  // The POSIX driver's description is long (time, file descriptor, buffer address, sizes):
  // its error number says it all.
  for (const ErrorRecord& e : stack)
    if (const int err = errno_in(e.description); err != 0) {
      out = std::strerror(err);
      break;
    }
  if (stack.size() > 1) out += " (in " + api.function + ": " + api.description + ")";
  return out;
}

}  // namespace grainflow
