#pragma once
// The run's output directory: created and proven writable before the first step, so a
// mistyped or read-only path fails at start-up instead of at the first snapshot hours in.
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

}  // namespace grainflow
