#pragma once
// One-dimensional HDF5 attributes (a value per material, say), shared by the snapshot and
// checkpoint writers and readers.
#include <hdf5.h>

#include <cstddef>
#include <vector>

namespace grainflow {

// Writes n values of the memory type `memory` at `loc` as the attribute `name`, stored as
// `file`. False on any HDF5 failure (the error stack is left for the caller to report).
inline bool write_array_attribute(hid_t loc, const char* name, hid_t file, hid_t memory,
                                  std::size_t n, const void* values) {
  const hsize_t dims[1] = {n};
  const hid_t space = H5Screate_simple(1, dims, nullptr);
  if (space < 0) return false;
  const hid_t attr = H5Acreate2(loc, name, file, space, H5P_DEFAULT, H5P_DEFAULT);
  const bool ok = attr >= 0 && H5Awrite(attr, memory, values) >= 0;
  if (attr >= 0) H5Aclose(attr);
  H5Sclose(space);
  return ok;
}

// Reads the attribute `name` at `loc` into `out` as the memory type `memory`: true with `out`
// empty when there is no such attribute, false when it exists but cannot be read.
template <class T>
bool read_array_attribute(hid_t loc, const char* name, hid_t memory, std::vector<T>& out) {
  out.clear();
  if (H5Aexists(loc, name) <= 0) return true;
  const hid_t attr = H5Aopen(loc, name, H5P_DEFAULT);
  const hid_t space = attr < 0 ? -1 : H5Aget_space(attr);
  const hssize_t n = space < 0 ? -1 : H5Sget_simple_extent_npoints(space);
  if (space >= 0) H5Sclose(space);
  bool ok = n >= 0;
  if (ok) {
    out.resize(static_cast<std::size_t>(n));
    ok = out.empty() || H5Aread(attr, memory, out.data()) >= 0;
  }
  if (attr >= 0) H5Aclose(attr);
  return ok;
}

}  // namespace grainflow
