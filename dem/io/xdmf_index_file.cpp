#include "dem/io/xdmf_index_file.hpp"

// Appending a time step to the XDMF index, and why every reachable state of the file parses.
//
// Facts relied on (Linux, a regular file, the writer killed with SIGKILL):
//  (K1) every write() that returned is in the file (page cache), whether or not it was synced;
//  (K2) a write() cut short by the kill is cut at a page boundary: a prefix of its bytes
//       whose end is a multiple of the page size (4 KiB here, or a multiple of 4 KiB, so a
//       write inside one 4 KiB-aligned block is all or nothing);
//  (X1) XML allows whitespace, comments and processing instructions (PIs) after the root
//       element; a PI "<?name text?>" ends at the first "?>", and its text may hold anything
//       else, including "<?" and "--" (comments could not: "--" is forbidden inside them, so
//       a comment cannot enclose the next one's opening; hence PIs here).
//
// Stable layout (XdmfIndexLayout): D = head, entries, spaces, T = render_xdmf_tail() at
// offset `tail`, E = xdmf_index_end_mark, end of file; [tail, tail + window) lies in one
// 4 KiB block, window = |T| + |E| + |S| with S = xdmf_index_stage_mark. The first such file is
// written whole and renamed into place (write_file_atomically); no write below touches it
// before the rename, and afterwards the file only changes by the five writes of an append.
//
// Appending entry G (render_xdmf_entry, no "?>" in it), with a = end of file = tail+|T|+|E|,
// c = a + |S|, and t' = c + |G| + p the new tail, p spaces chosen so that [t', t' + window)
// lies in one block:
//  W1  spaces over [a, t' + |T| + |E|)      any prefix: D + spaces         (X1)  old set
//                                           (the file's new size: the writes below only
//                                           overwrite, so a full disk can stop only W1)
//  W2  E at t' + |T|                        one block (inside the new window):
//                                           D + spaces + E                 (X1)  old set
//  W3  S at a                               one block (inside the old window): a PI opens at
//                                           a; its text (spaces, "<?grainflow-end") holds no
//                                           "?>", so it ends with E's "?>"  (X1)  old set
//  W4  G, p spaces, T over [c, t' + |T|)    any prefix: bytes inside that PI's text change;
//                                           G and T hold no "?>" and the PI's end is beyond
//                                           them, so it still ends with E's "?>"; old set
//  W5  spaces over [tail, c)                one block (the old window): the old tail, the old
//                                           end mark and the stage mark become whitespace
//                                           between the entries, so G is the collection's last
//                                           element, T closes the document at t', and E is a
//                                           PI after the root.             new set, layout
//                                           (t', t' + |T| + |E|)
// Every state reachable by (K1)/(K2) is one of those listed, so it parses and lists either the
// old or the new entries. Cost: |G| + about 2 x window bytes written twice, five pwrite calls,
// no fsync (which protects against power loss, not against a kill: docs/reliability.md).
// Checked write by write and byte prefix by byte prefix with Python's XML parser in
// tests/dem/io/xdmf_index_file_test.cpp.

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "dem/io/output_directory.hpp"

namespace grainflow {

namespace {

// The unit within which a write is all or nothing under SIGKILL (K2): the smallest page size
// of Linux; a 4 KiB-aligned block also lies inside one larger page.
constexpr std::size_t block = 4096;

bool in_one_block(std::size_t offset, std::size_t size) {
  return size == 0 || offset / block == (offset + size - 1) / block;
}

// Spaces that move `at` forward so that [at, at + window) lies in one block.
std::size_t padding_for_window(std::size_t at) {
  const std::size_t window = xdmf_index_tail_window();
  return in_one_block(at, window) ? 0 : block - at % block;
}

std::size_t length(const char* s) { return std::strlen(s); }

[[noreturn]] void fail(const std::string& path, const std::string& what, int err) {
  throw OutputError("cannot write '" + path + "': " + what + ": " + std::strerror(err) +
                    ". Check free space and permissions of the output directory.");
}

}  // namespace

std::size_t xdmf_index_tail_window() {
  return render_xdmf_tail().size() + length(xdmf_index_end_mark) + length(xdmf_index_stage_mark);
}

std::string render_xdmf_appendable(const std::vector<XdmfEntry>& entries,
                                   const std::string& series_name, XdmfIndexLayout& layout) {
  std::string out = render_xdmf_head(series_name);
  for (const XdmfEntry& e : entries) out += render_xdmf_entry(e);
  out.append(padding_for_window(out.size()), ' ');
  layout.tail = out.size();
  out += render_xdmf_tail();
  out += xdmf_index_end_mark;
  layout.end = out.size();
  return out;
}

std::vector<XdmfIndexWrite> plan_xdmf_append(const XdmfIndexLayout& now,
                                             const std::string& entry_xml, XdmfIndexLayout& next) {
  if (entry_xml.find("?>") != std::string::npos)
    throw std::logic_error("plan_xdmf_append: an index entry must not contain \"?>\"");
  const std::string tail = render_xdmf_tail();
  const std::size_t end_mark = length(xdmf_index_end_mark);
  const std::size_t stage_mark = length(xdmf_index_stage_mark);
  if (now.end != now.tail + tail.size() + end_mark ||
      !in_one_block(now.tail, xdmf_index_tail_window()))
    throw std::logic_error("plan_xdmf_append: the layout is not one render_xdmf_appendable makes");

  const std::size_t a = now.end;
  const std::size_t c = a + stage_mark;
  const std::size_t pad = padding_for_window(c + entry_xml.size());
  next.tail = c + entry_xml.size() + pad;
  next.end = next.tail + tail.size() + end_mark;

  std::string staged = entry_xml;
  staged.append(pad, ' ');
  staged += tail;
  std::vector<XdmfIndexWrite> writes;
  writes.reserve(5);
  writes.push_back({a, std::string(next.end - a, ' '), false});
  writes.push_back({next.tail + tail.size(), xdmf_index_end_mark, true});
  writes.push_back({a, xdmf_index_stage_mark, true});
  writes.push_back({c, std::move(staged), false});
  writes.push_back({now.tail, std::string(c - now.tail, ' '), true});
  for (const XdmfIndexWrite& w : writes)
    if (w.in_one_block && !in_one_block(w.offset, w.bytes.size()))
      throw std::logic_error("plan_xdmf_append: a switching write crosses a 4 KiB boundary");
  return writes;
}

XdmfIndexFile::XdmfIndexFile(std::string path, const std::string& series_name,
                             const std::vector<XdmfEntry>& entries)
    : path_(std::move(path)) {
  write_file_atomically(path_, render_xdmf_appendable(entries, series_name, layout_));
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd_ < 0) fail(path_, "cannot open it to append", errno);
}

XdmfIndexFile::~XdmfIndexFile() {
  if (fd_ >= 0) ::close(fd_);
}

void XdmfIndexFile::append(const XdmfEntry& entry) {
  XdmfIndexLayout next;
  for (const XdmfIndexWrite& w : plan_xdmf_append(layout_, render_xdmf_entry(entry), next)) {
    std::size_t done = 0;
    while (done < w.bytes.size()) {
      const ssize_t n = ::pwrite(fd_, w.bytes.data() + done, w.bytes.size() - done,
                                 static_cast<off_t>(w.offset + done));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) fail(path_, "cannot append a time step", n < 0 ? errno : EIO);
      done += static_cast<std::size_t>(n);
    }
  }
  layout_ = next;
}

}  // namespace grainflow
