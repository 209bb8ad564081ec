// XDMF index text and the atomic file replacement, serially. Reference: the XDMF 2 layout
// described in xdmf_index.hpp; no numerical tolerance (times are printed with 17 significant
// digits and must read back exactly).
#include "dem/io/xdmf_index.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dem/io/output_directory.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;

fs::path fresh_directory(const std::string& name) {
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "xdmf_index_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1))
    ++n;
  return n;
}

TEST(XdmfIndex, EmptySeriesIsACompleteDocument) {
  const std::string xml = render_xdmf({}, "particles");
  EXPECT_NE(xml.find("CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_EQ(count(xml, "<Grid "), 1u);
  EXPECT_EQ(xml.substr(xml.size() - 8), "</Xdmf>\n");
}

// Each time step is a Spatial collection; a snapshot of no particle is one without a particles
// grid (ParaView's XDMF 2 reader fails on a geometry of no points), not a grid of zero points.
TEST(XdmfIndex, ASnapshotOfNoParticleIsAnEmptyCollection) {
  const std::string xml =
      render_xdmf({{"p_000000.h5", 0.0, 0, 0}, {"p_000001.h5", 0.1, 10, 4}}, "p");
  EXPECT_EQ(count(xml, "CollectionType=\"Spatial\""), 2u);
  EXPECT_EQ(count(xml, "<Grid Name=\"particles\""), 1u);
  EXPECT_EQ(count(xml, "<Time "), 2u);
  EXPECT_EQ(count(xml, "p_000000.h5"), 0u);  // nothing of the empty file is read
  EXPECT_EQ(count(xml, "NumberOfElements=\"0\""), 0u);
  EXPECT_EQ(count(xml, "Dimensions=\"4 3\">p_000001.h5:/position<"), 1u);
}

TEST(XdmfIndex, TimeIsPrintedToFullPrecision) {
  const double t = 1.0 / 3.0;
  const std::string xml = render_xdmf({{"p_000000.h5", t, 3, 2}}, "p");
  const std::size_t at = xml.find("<Time Value=\"");
  ASSERT_NE(at, std::string::npos);
  EXPECT_EQ(std::strtod(xml.c_str() + at + 13, nullptr), t);
}

TEST(XdmfIndex, EveryFieldIsReferencedWithItsShape) {
  const SnapshotFieldSet all = (SnapshotFieldSet{1} << snapshot_fields.size()) - 1;
  const std::string xml = render_xdmf({{"s_000004.h5", 0.5, 50, 12, all}}, "s");
  for (const SnapshotField& f : snapshot_fields) {
    const std::string dims = f.components == 1 ? "12" : "12 3";
    const std::string ref = std::string("Dimensions=\"") + dims + "\">s_000004.h5:/" + f.name + "<";
    EXPECT_EQ(count(xml, ref), 1u) << ref;
  }
  EXPECT_NE(xml.find("<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"12\""),
            std::string::npos);
}

// Each grid lists the fields its file holds: the default set, or the set of output.fields.
TEST(XdmfIndex, GridsListOnlyTheFieldsTheirFileHolds) {
  const std::string plain = render_xdmf({{"p_000000.h5", 0.0, 0, 3}}, "p");
  EXPECT_EQ(count(plain, "<Attribute "), 7u);  // the default eight, less the geometry
  EXPECT_EQ(count(plain, ":/force<"), 0u);
  const SnapshotFieldSet some =
      snapshot_required_fields | snapshot_field_bit("force") | snapshot_field_bit("coordination");
  const std::string xml = render_xdmf({{"p_000001.h5", 0.1, 1, 3, some}}, "p");
  EXPECT_EQ(count(xml, "<Attribute "), 3u);  // id, force, coordination
  EXPECT_EQ(count(xml, "<Attribute Name=\"force\" AttributeType=\"Vector\""), 1u);
  EXPECT_EQ(count(xml, "<Attribute Name=\"coordination\" AttributeType=\"Scalar\""), 1u);
  EXPECT_EQ(count(xml, "NumberType=\"Int\" Precision=\"4\" Dimensions=\"3\">p_000001.h5:/coordination<"),
            1u);
  EXPECT_EQ(count(xml, ":/velocity<"), 0u);
}

TEST(XdmfIndex, SpecialCharactersAreEscaped) {
  const std::string xml = render_xdmf({{"a&b<c>_000000.h5", 0.0, 0, 1}}, "a&b<c>");
  EXPECT_EQ(xml.find("a&b"), std::string::npos);
  EXPECT_NE(xml.find("a&amp;b&lt;c&gt;_000000.h5:/position"), std::string::npos);
}

TEST(XdmfIndex, AtomicWriteReplacesAndLeavesNoTemporary) {
  const fs::path dir = fresh_directory("atomic");
  const fs::path path = dir / "index.xdmf";
  write_file_atomically(path.string(), "first\n");
  write_file_atomically(path.string(), "second\n");
  EXPECT_EQ(slurp(path), "second\n");
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
}

TEST(XdmfIndex, AtomicWriteIntoMissingDirectoryNamesPath) {
  const fs::path path = fresh_directory("missing") / "no" / "index.xdmf";
  try {
    write_file_atomically(path.string(), "x");
    ADD_FAILURE() << "no OutputError";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace grainflow
