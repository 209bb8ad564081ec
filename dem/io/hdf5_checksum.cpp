#include "dem/io/hdf5_checksum.hpp"

#include <algorithm>
#include <cctype>

#include "dem/io/hdf5_errors.hpp"

namespace grainflow {

bool add_checksum(hid_t dcpl, int rank, const hsize_t* dims, std::size_t element_bytes) {
  if (dims[0] == 0) return true;
  const hsize_t row_bytes = (rank == 2 ? dims[1] : 1) * std::max<std::size_t>(element_bytes, 1);
  // Equal chunks of at most 1 MiB: HDF5 allocates whole chunks, so a last chunk mostly
  // empty would waste its size in the file.
  const hsize_t max_rows = std::max<hsize_t>((hsize_t(1) << 20) / row_bytes, 1);
  const hsize_t chunks = (dims[0] + max_rows - 1) / max_rows;
  const hsize_t rows = (dims[0] + chunks - 1) / chunks;
  const hsize_t chunk[2] = {rows, rank == 2 ? dims[1] : 1};
  return H5Pset_chunk(dcpl, rank, chunk) >= 0 && H5Pset_fletcher32(dcpl) >= 0;
}

hid_t checksummed_layout(int rank, const hsize_t* dims, std::size_t element_bytes) {
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  if (dcpl >= 0 && !add_checksum(dcpl, rank, dims, element_bytes)) {
    H5Pclose(dcpl);
    return -1;
  }
  return dcpl;
}

std::string read_failure_reason() {
  std::string reason = hdf5_reason();
  std::string lower = reason;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower.find("fletcher32") != std::string::npos)
    return "its Fletcher32 checksum does not match the data (" + reason +
           "): the file was changed or damaged after it was written";
  return reason;
}

}  // namespace grainflow
