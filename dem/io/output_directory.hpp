#pragma once
// The run's output directory: created and proven writable before the first step, so a
// mistyped or read-only path fails at start-up instead of at the first snapshot hours in.
#include <mpi.h>

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

// Collective. Rank 0 holds an exclusive lock (flock) on `<dir>/.grain.lock` for the object's
// life, so that a second run into the same directory is refused at its start instead of
// writing snapshots, log rows and checkpoints of the same names as this run's (two runs, one
// folder: both exit 0, the index declares one run's particle count for the other's files, and
// the log splices their rows). The file holds "pid host" of the holder, quoted by the refusal;
// it is removed when the object ends (a killed run leaves it, unlocked: the next run takes it).
// A file system without flock (ENOLCK, EOPNOTSUPP) runs unlocked. Throws OutputError on every
// rank when another process holds the lock.
class OutputLock {
 public:
  OutputLock(MPI_Comm comm, const std::string& dir);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

 private:
  int fd_ = -1;
  std::string path_;
};

// For the message of a failed write of a file of about `bytes` into `dir`, when the layers in
// between do not pass the OS error on (MPI-IO reports a short write, not ENOSPC): "No space left
// on device: N bytes are free on the file system of 'dir', the file needs about M" when fewer
// than `bytes` are free there (measured with statvfs), else "".
std::string no_space_note(const std::string& dir, std::uintmax_t bytes);

}  // namespace grainflow
