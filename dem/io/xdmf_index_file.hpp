#pragma once
// The XDMF index of a snapshot series as a file that grows by one time step per snapshot in
// O(1) bytes written and without fsync, and that parses as valid XML listing either the old or
// the new set of time steps whatever moment the writing process is killed (SIGKILL) at. The
// scheme and its proof are in xdmf_index_file.cpp; docs/reliability.md says what is
// guaranteed (and what is not: power loss).
#include <cstddef>
#include <string>
#include <vector>

#include "dem/io/xdmf_index.hpp"

namespace grainflow {

// Where an appendable index keeps its live tail: the file is
//   head, the entries, spaces, render_xdmf_tail() at `tail`, xdmf_index_end_mark, end of file,
// with [tail, tail + xdmf_index_tail_window) inside one 4 KiB-aligned block.
struct XdmfIndexLayout {
  std::size_t tail = 0;  // offset of the live tail's first byte
  std::size_t end = 0;   // file size
};

// One write of an append: `bytes` at file offset `offset`, in this order. A write marked
// `in_one_block` lies within one 4 KiB-aligned block of the file (all or nothing under
// SIGKILL); every other write leaves a valid file after any prefix of its bytes.
struct XdmfIndexWrite {
  std::size_t offset;
  std::string bytes;
  bool in_one_block;
};

// A processing instruction after the root element that ends the staging instruction of the
// next append (xdmf_index_file.cpp).
inline constexpr const char* xdmf_index_end_mark = "<?grainflow-end?>\n";
// Opens the processing instruction an entry is staged in before it is switched on.
inline constexpr const char* xdmf_index_stage_mark = "<?grainflow-staged ";
// Bytes from the live tail that must not cross a 4 KiB boundary: the tail, the end mark and
// the next append's stage mark, which its last write overwrites in one go.
std::size_t xdmf_index_tail_window();

// The whole appendable file for `entries`, and its layout.
std::string render_xdmf_appendable(const std::vector<XdmfEntry>& entries,
                                   const std::string& series_name, XdmfIndexLayout& layout);

// The writes that append `entry_xml` (one render_xdmf_entry) to a file of layout `now`; `next`
// receives the layout after them. Throws std::logic_error if `entry_xml` contains "?>".
std::vector<XdmfIndexWrite> plan_xdmf_append(const XdmfIndexLayout& now,
                                             const std::string& entry_xml, XdmfIndexLayout& next);

class XdmfIndexFile {
 public:
  // Replaces `path` by the index of `entries` (write_file_atomically, the one fsync) and keeps
  // it open for append(). Throws OutputError naming the path and the reason.
  XdmfIndexFile(std::string path, const std::string& series_name,
                const std::vector<XdmfEntry>& entries);
  ~XdmfIndexFile();
  XdmfIndexFile(const XdmfIndexFile&) = delete;
  XdmfIndexFile& operator=(const XdmfIndexFile&) = delete;

  // Adds one time step (plan_xdmf_append, written with pwrite). Throws OutputError naming the
  // path and the reason; the file then still lists the earlier entries, and this object must
  // be replaced (a new constructor call rewrites the file whole).
  void append(const XdmfEntry& entry);

  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
  XdmfIndexLayout layout_;
};

}  // namespace grainflow
