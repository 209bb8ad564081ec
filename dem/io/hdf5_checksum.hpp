#pragma once
// Checksums of every dataset grainflow writes (checkpoints, particle snapshots): HDF5's own
// Fletcher32 filter stores a checksum with each chunk and verifies it whenever the chunk is
// read, so a changed or damaged value fails the read instead of entering a run.
#include <hdf5.h>

#include <cstddef>
#include <cstdint>
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

// The rows of one chunk of such a dataset (all chunks hold this many; the last may run past
// the end of the data).
hsize_t checksum_chunk_rows(int rank, const hsize_t* dims, std::size_t element_bytes);

// The Fletcher32 checksum HDF5's filter stores after each chunk (HDF5's H5checksum.c: the
// data as big-endian 16-bit words, a trailing odd byte as the high byte of one more; both
// sums modulo 65535, kept as 65535 rather than 0 once a word was non-zero; stored
// little-endian after the chunk as sum2 << 16 | sum1). The same value as HDF5's routine,
// computed eight words at a time.
std::uint32_t fletcher32(const void* data, std::size_t bytes);

// Writes the whole of a dataset created with checksummed_layout / add_checksum (same rank,
// dims and element size) from `data`, whose bytes are already those of the file's type
// (the caller checks that the memory and file types agree), one chunk at a time through
// H5Dwrite_chunk with the checksums above: the chunk bypasses HDF5's filter pipeline, which
// copies each chunk twice and sums it a word at a time. The file is the same as H5Dwrite's,
// and HDF5 verifies every chunk on reading as usual. Serial files only (parallel HDF5 has no
// direct chunk writes). False on failure (hdf5_reason() has HDF5's message).
bool write_checksummed(hid_t dataset, int rank, const hsize_t* dims, std::size_t element_bytes,
                       const void* data);

// After a successful H5Dread of a whole non-empty dataset into `values` (memory type
// `mem_type`): why those values cannot be trusted to be the ones stored, or "" when they can.
// HDF5 verifies the Fletcher32 checksum of each chunk it finds, but a damaged chunk index (a
// chunk recorded at a wrong offset, a filter mask saying the checksum was skipped) makes it
// read the fill value, zeros, with no error. So each chunk of a checksummed dataset (the rows
// it covers, as written: whole rows per chunk) is read again raw (H5Dread_chunk): it must
// exist, carry its checksum, match it, and hold the bytes H5Dread returned (when the memory
// type is the file's). With `require_checksum` (files written with checksums on every
// dataset) a dataset without the Fletcher32 filter is refused too: its filter record was
// damaged.
std::string verify_stored(hid_t dataset, hid_t mem_type, const void* values, bool require_checksum);

// After a failed H5Dread: the reason in one line (hdf5_reason()), and when HDF5's Fletcher32
// check failed, a sentence saying that the data differ from what was written.
std::string read_failure_reason();

}  // namespace grainflow
