#pragma once
// An HDF5 file driver for files written once by one process (snapshots, checkpoints): the
// bytes and the file are exactly those of HDF5's default POSIX driver ("sec2"), and any
// HDF5 reader opens them as usual. What differs is how large writes reach the disk: the
// whole 4 KiB blocks inside a write of at least kDirectWriteMin bytes (a dataset's chunks,
// up to 1 MiB each) go through a second descriptor opened with O_DIRECT, bypassing the page
// cache; the ends of such writes, and every smaller write (metadata), take the ordinary
// buffered path. Reads are ordinary reads, which Linux keeps coherent with direct writes.
//
// Why: a write into the page cache must first obtain a fresh page for every 4 KiB, and on
// virtual machines whose free memory goes back to the host (virtio-balloon free page
// reporting, likely the cause on this project's reference machine) that ran at 163-247 MB/s
// against 1.2-2.6 GB/s for direct writes of 1-8 MiB blocks (docs/performance.md, "Snapshot
// writes and the page cache"). On a file system that refuses O_DIRECT (some network file
// systems; older tmpfs) the second descriptor does not open, or its first write fails with
// EINVAL, and every byte takes the buffered path: the same file, at the page cache's speed.
#include <hdf5.h>

#include <cstddef>
#include <string>

namespace grainflow {

// Writes smaller than this take the buffered path whole.
inline constexpr std::size_t kDirectWriteMin = 256 * 1024;

// Sets the driver on a file-access property list (registering it with HDF5 on first use).
// False when HDF5 refused (the list keeps its previous driver), or when the environment variable
// GRAINFLOW_BUFFERED_WRITES holds a value other than 0 or 1 (HDF5's error stack then says so,
// for hdf5_reason()). With GRAINFLOW_BUFFERED_WRITES=1 it leaves the list as it is (true): every
// write through the page cache, which returns at memory speed and reaches the disk in the
// background - faster where the disk is slower than the page cache can take fresh pages (a spinning
// disk, some network file systems), slower on guests like this project's (docs/performance.md).
bool set_direct_write_driver(hid_t fapl);

// The message for a value of GRAINFLOW_BUFFERED_WRITES other than 0 or 1 (naming it and the
// allowed values); empty when it is unset, empty, 0 or 1.
std::string buffered_writes_error();

// Bytes written with O_DIRECT by this process since it started (all files; for tests and the
// benchmark's report).
long long direct_write_bytes();

}  // namespace grainflow
