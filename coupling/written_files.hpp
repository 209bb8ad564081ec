#pragma once
// The files grainFoam wrote in one time folder, and a check that they are still those files
// when a run restarts from it.
//
// OpenFOAM's field files carry no checksum: a flipped bit in a binary U (a failing disk, a
// damaged copy) restarts another run without a word, and so does a changed digit in an ascii
// one. At each write time grainFoam lists every file of the time folder with its FNV-1a 64-bit
// checksum in `grainflowChecksums` (record_written_files); a restart from that folder reads
// them again (check_written_files) and stops at any difference, naming the file. A change
// made on purpose is accepted by deleting that file's line.
//
// FNV-1a (Fowler, Noll & Vo; IETF draft-eastlake-fnv): any change confined to one byte
// changes the checksum, since each step (xor, multiplication by an odd prime modulo 2^64) is
// a bijection of the state; other changes go unseen with probability 2^-64.
//
// The record is a dictionary (OpenFOAM tools read its FoamFile header and leave it alone;
// decomposePar and reconstructPar do not copy it, so a folder they rewrote has none and is
// read unchecked).
//
// C++17, standard headers only: compiled into the OpenFOAM solver as well.
#include <cstdint>
#include <string>
#include <string_view>

namespace grainflow::coupling {

// The record's name in each time folder.
inline constexpr const char* kWrittenFilesRecord = "grainflowChecksums";

// FNV-1a 64-bit of bytes, continuing from `state` (the offset basis to start).
inline constexpr std::uint64_t kFnvOffsetBasis = 0xcbf29ce484222325ULL;
std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t state = kFnvOffsetBasis);

// FNV-1a 64-bit of a file's bytes; throws std::runtime_error naming the file when it cannot
// be read.
std::uint64_t file_checksum(const std::string& path);

// Writes `folder`/grainflowChecksums: every regular file under `folder` (sub-folders such as
// uniform/ too) with its checksum; `who` says which run wrote them (e.g. "processor1 of 2
// ranks, time 0.02"). Returns the number of files listed; throws std::runtime_error naming
// the file that could not be read or written.
int record_written_files(const std::string& folder, const std::string& who);

struct WrittenFilesCheck {
  bool recorded = false;  // the folder has a record
  int checked = 0;        // files that match it
  std::string problem;    // empty, or what differs and what to do (a whole message)
};

// Compares the files of `folder` with its record (none: recorded false, nothing checked).
// Files not in the record are not checked (a post-processing utility's output).
WrittenFilesCheck check_written_files(const std::string& folder);

}  // namespace grainflow::coupling
