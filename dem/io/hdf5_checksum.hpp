#pragma once
// Checksums of every dataset grainflow writes (checkpoints, particle snapshots): HDF5's own
// Fletcher32 filter stores a checksum with each chunk and verifies it whenever the chunk is
// read, so a changed or damaged value fails the read instead of entering a run.
#include <hdf5.h>

#include <cstddef>
#include <string>

namespace grainflow {

// A new dataset-creation property list (close it with H5Pclose; -1 on failure) for a dataset
// of `rank` (1 or 2) dimensions `dims` and `element_bytes` per element: chunked, with the
// Fletcher32 filter. Chunks hold whole rows, at most 1 MiB, all of about equal size (HDF5
// allocates whole chunks), so a 30 000-particle position array is one chunk. An empty dataset keeps
// the contiguous layout (no data to check; a chunk may not exceed a fixed dimension of 0).
hid_t checksummed_layout(int rank, const hsize_t* dims, std::size_t element_bytes);
// The same settings added to an existing dataset-creation property list; false on failure.
bool add_checksum(hid_t dcpl, int rank, const hsize_t* dims, std::size_t element_bytes);

// After a failed H5Dread: the reason in one line (hdf5_reason()), and when HDF5's Fletcher32
// check failed, a sentence saying that the data differ from what was written.
std::string read_failure_reason();

}  // namespace grainflow
