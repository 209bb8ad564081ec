#pragma once
// The run's output directory: created and proven writable before the first step, so a
// mistyped or read-only path fails at start-up instead of at the first snapshot hours in.
#include <cstdint>
#include <stdexcept>
#include <string>

namespace grainflow {

// Every failure to create, write or rename an output file (snapshot, XDMF index, log table,
// output directory). The message names the path and the operating system's or HDF5's reason.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Creates `dir` and its parents (mkdir -p) and checks that files can be created in it by
// writing and removing a probe file. Throws OutputError naming the path and the OS reason.
// Safe to call from every rank at once (each rank uses its own probe name).
void prepare_output_directory(const std::string& dir);

// For the message of a failed write of a file of about `bytes` into `dir`, when the layers in
// between do not pass the OS error on (MPI-IO reports a short write, not ENOSPC): "No space left
// on device: N bytes are free on the file system of 'dir', the file needs about M" when fewer
// than `bytes` are free there (measured with statvfs), else "".
std::string no_space_note(const std::string& dir, std::uintmax_t bytes);

}  // namespace grainflow
