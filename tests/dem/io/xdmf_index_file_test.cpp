// The appendable XDMF index (dem/io/xdmf_index_file.cpp): every state of the file that a
// SIGKILL can leave while an entry is appended parses as XML and lists either the old or the
// new time steps. The reference is Python's XML parser (xml.etree, expat) reading each state,
// compared with the same parser reading render_xdmf of the old and of the new entry list; a
// state "can be left" when it is the file after some writes of the append plus a prefix of
// the next one: any prefix for writes that cross a 4 KiB boundary (Linux cuts a killed
// write only at page boundaries, so this is more than can happen), all or nothing for those
// inside one block. The real file written with pwrite must equal the simulated one byte for
// byte.
#include "dem/io/xdmf_index_file.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace grainflow {
namespace {

namespace fs = std::filesystem;

fs::path fresh_directory(const std::string& name) {
  const fs::path dir =
      fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "xdmf_index_file_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Reads states (each "<size>\n<bytes>") and prints one line per state: "ok <the document with
// every text and tail stripped, comments and PIs dropped>" or "error <parser message>".
const char* parse_states_script = R"PY(
import sys, xml.etree.ElementTree as ET
data = open(sys.argv[1], "rb").read()
at = 0
while at < len(data):
    nl = data.index(b"\n", at)
    size = int(data[at:nl])
    doc = data[nl + 1:nl + 1 + size]
    at = nl + 1 + size
    try:
        root = ET.fromstring(doc)
    except ET.ParseError as e:
        print("error", e)
        continue
    for e in root.iter():
        e.text = None
        e.tail = None
    print("ok", ET.tostring(root, encoding="unicode"))
)PY";

std::vector<std::string> parse_states(const fs::path& dir, const std::vector<std::string>& states) {
  const fs::path script = dir / "parse_states.py";
  std::ofstream(script) << parse_states_script;
  const fs::path input = dir / "states.bin";
  {
    std::ofstream out(input, std::ios::binary);
    for (const std::string& s : states) out << s.size() << '\n' << s;
  }
  const std::string command = std::string(GRAINFLOW_SOURCE_DIR "/scripts/python.sh ") +
                              script.string() + " " + input.string() + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run " + command);
  std::string text;
  char buf[65536];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) text.append(buf, n);
  const int status = ::pclose(pipe);
  if (status != 0) throw std::runtime_error(command + " failed:\n" + text);
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

void apply(std::string& file, const XdmfIndexWrite& w, std::size_t prefix) {
  if (file.size() < w.offset + prefix) file.resize(w.offset + prefix, '\0');  // a hole reads 0
  file.replace(w.offset, prefix, w.bytes, 0, prefix);
}

XdmfEntry entry(std::size_t k) {
  // Field sets of different sizes, so that appends land at many offsets within a 4 KiB block.
  const SnapshotFieldSet all = (SnapshotFieldSet{1} << snapshot_fields.size()) - 1;
  const SnapshotFieldSet sets[] = {snapshot_default_fields, snapshot_required_fields, all,
                                   snapshot_required_fields | snapshot_field_bit("force")};
  char name[32];
  std::snprintf(name, sizeof name, "particles_%06zu.h5", k);
  return {name, 1e-3 * static_cast<double>(k) + 1.0 / 3.0, static_cast<long>(10 * k),
          static_cast<long>(2 + 7 * k), sets[k % 4]};
}

// The states to parse: each with the state whose parse it must equal (a reference document).
struct Batch {
  std::vector<std::string> states;
  std::vector<std::size_t> must_equal;  // index into states; a reference points to itself
  std::size_t appends_checked = 0;      // states that are not references
  std::vector<std::size_t> old_refs;    // each append's old reference; its new one follows
};

// Appends `e` to `file` (layout `layout`, listing `entries`) by the plan, adding to `batch` the
// states a kill can leave, each to parse as the old listing until the last write completes
// and as the new one after it. `every_byte`: every prefix of a write that crosses a block
// boundary, else only its prefixes that end on a boundary (what Linux can leave).
void append_states(std::string& file, XdmfIndexLayout& layout, std::vector<XdmfEntry>& entries,
                   const XdmfEntry& e, bool every_byte, Batch& batch) {
  const std::size_t old_ref = batch.states.size();
  batch.old_refs.push_back(old_ref);
  batch.states.push_back(render_xdmf(entries, "particles"));
  batch.must_equal.push_back(old_ref);
  entries.push_back(e);
  const std::size_t new_ref = batch.states.size();
  batch.states.push_back(render_xdmf(entries, "particles"));
  batch.must_equal.push_back(new_ref);
  const auto add = [&](const std::string& state, bool is_new) {
    batch.states.push_back(state);
    batch.must_equal.push_back(is_new ? new_ref : old_ref);
    ++batch.appends_checked;
  };
  add(file, false);

  XdmfIndexLayout next;
  const std::vector<XdmfIndexWrite> plan = plan_xdmf_append(layout, render_xdmf_entry(e), next);
  EXPECT_EQ(plan.size(), 5u);
  for (std::size_t k = 0; k < plan.size(); ++k) {
    const XdmfIndexWrite& w = plan[k];
    if (w.in_one_block) {
      EXPECT_EQ(w.offset / 4096, (w.offset + w.bytes.size() - 1) / 4096) << "write " << k;
    } else {
      for (std::size_t p = 1; p < w.bytes.size(); ++p) {
        if (!every_byte && (w.offset + p) % 4096 != 0) continue;
        std::string partial = file;
        apply(partial, w, p);
        add(partial, false);
      }
    }
    apply(file, w, w.bytes.size());
    add(file, k + 1 == plan.size());
  }
  layout = next;
  EXPECT_EQ(file.size(), layout.end);
  EXPECT_EQ(file.substr(layout.tail, layout.end - layout.tail),
            render_xdmf_tail() + xdmf_index_end_mark);
}

// Parses every state of the batch; returns how many parsed as the listing they must have.
std::size_t check(const fs::path& dir, const Batch& batch) {
  const std::vector<std::string> lines = parse_states(dir, batch.states);
  EXPECT_EQ(lines.size(), batch.states.size());
  if (lines.size() != batch.states.size()) return 0;
  std::size_t matched = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::size_t ref = batch.must_equal[i];
    if (ref == i) {  // a reference document
      EXPECT_EQ(lines[i].rfind("ok ", 0), 0u) << lines[i];
      continue;
    }
    EXPECT_EQ(lines[i], lines[ref]) << "state " << i << ":\n" << batch.states[i];
    matched += lines[i] == lines[ref];
  }
  for (std::size_t ref : batch.old_refs) EXPECT_NE(lines[ref], lines[ref + 1]);
  return matched;
}

// One append, every byte prefix of every write that crosses a block boundary: about 4000
// states, each parsed.
TEST(XdmfIndexFile, EveryPrefixOfAnAppendParsesAsTheOldOrNewIndex) {
  const fs::path dir = fresh_directory("every_prefix");
  std::vector<XdmfEntry> entries = {entry(0), entry(1)};
  XdmfIndexLayout layout;
  std::string file = render_xdmf_appendable(entries, "particles", layout);
  Batch batch;
  append_states(file, layout, entries, entry(2), true, batch);
  EXPECT_GT(batch.appends_checked, 1000u);
  EXPECT_EQ(check(dir, batch), batch.appends_checked);
}

// 40 appends of entries of four sizes (the file crosses many 4 KiB boundaries, the tail
// window is padded past them), the states Linux can leave; then the same appends through
// XdmfIndexFile must give the same bytes.
TEST(XdmfIndexFile, ManyAppendsAcrossBlockBoundariesAndTheRealFileAgree) {
  const fs::path dir = fresh_directory("many");
  std::vector<XdmfEntry> entries = {entry(0)};
  XdmfIndexLayout layout;
  std::string file = render_xdmf_appendable(entries, "particles", layout);
  const fs::path path = dir / "particles.xdmf";
  XdmfIndexFile real(path.string(), "particles", entries);
  EXPECT_EQ(slurp(path), file);
  Batch batch;
  for (std::size_t k = 1; k <= 40; ++k) {
    const XdmfEntry e = entry(k);
    append_states(file, layout, entries, e, false, batch);
    real.append(e);
    ASSERT_EQ(slurp(path), file) << "after append " << k;
  }
  EXPECT_GT(file.size(), 40000u);  // about ten blocks
  EXPECT_GE(batch.appends_checked, 40u * 6);
  EXPECT_EQ(check(dir, batch), batch.appends_checked);
  // A new XdmfIndexFile (a restart) rewrites the file whole.
  XdmfIndexFile again(path.string(), "particles", {entry(0)});
  XdmfIndexLayout fresh;
  EXPECT_EQ(slurp(path), render_xdmf_appendable({entry(0)}, "particles", fresh));
}

TEST(XdmfIndexFile, AnEntryWithAProcessingInstructionEndIsRefused) {
  XdmfIndexLayout layout, next;
  render_xdmf_appendable({}, "p", layout);
  EXPECT_THROW(plan_xdmf_append(layout, "<Grid Name=\"?>\"/>", next), std::logic_error);
}

// Appending costs O(1) bytes: the bytes written for the 1000th entry equal those for the
// 2nd (same entry size, same padding), unlike a rewrite of the whole index.
TEST(XdmfIndexFile, AppendWritesBytesIndependentOfTheIndexLength) {
  XdmfIndexLayout layout;
  std::vector<XdmfEntry> entries = {entry(0)};
  render_xdmf_appendable(entries, "p", layout);
  std::size_t first = 0, largest = 0;
  const std::string xml = render_xdmf_entry(entry(4));  // the same entry every time
  for (int k = 0; k < 1000; ++k) {
    XdmfIndexLayout next;
    std::size_t bytes = 0;
    for (const XdmfIndexWrite& w : plan_xdmf_append(layout, xml, next)) bytes += w.bytes.size();
    if (k == 0) first = bytes;
    largest = std::max(largest, bytes);
    layout = next;
  }
  // Within 2 x the window of padding (the tail moved past a block boundary).
  EXPECT_LE(largest, first + 2 * xdmf_index_tail_window());
  EXPECT_LT(largest, 3 * xml.size());
}

}  // namespace
}  // namespace grainflow
