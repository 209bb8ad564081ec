// The contact network in the XDMF index, serially. Reference: the XDMF 2 layout described in
// xdmf_index.hpp and contact_network.hpp (a Spatial collection per time of the particles'
// Polyvertex grid and one Polyline grid per contact group, 2 nodes per line, cell
// attributes). Text only: ParaView's reading of it is checked by contact_network_paraview.
#include <gtest/gtest.h>

#include <string>

#include "dem/io/contact_network.hpp"
#include "dem/io/xdmf_index.hpp"

namespace grainflow {
namespace {

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1))
    ++n;
  return n;
}

XdmfEntry with_network(long pairs, long walls) {
  XdmfEntry e{"p_000002.h5", 0.25, 40, 30};
  e.contacts = pairs;
  e.wall_contacts = walls;
  return e;
}

TEST(XdmfContacts, EntryWithoutNetworkHoldsTheParticlesAlone) {
  const XdmfEntry plain{"p_000000.h5", 0, 0, 30};
  EXPECT_EQ(render_contact_grids(plain, "  "), "");
  const std::string xml = render_xdmf({plain}, "p");
  EXPECT_EQ(count(xml, "Spatial"), 1u);
  EXPECT_EQ(count(xml, "<Grid "), 1u + 1u + 1u);  // series, the time's collection, particles
  EXPECT_EQ(count(xml, "Polyline"), 0u);
}

TEST(XdmfContacts, LinesOfTwoNodesWithCellAttributes) {
  const std::string grids = render_contact_grids(with_network(7, 3), "    ");
  EXPECT_EQ(count(grids, "<Grid Name=\"contacts\" GridType=\"Uniform\">"), 1u);
  EXPECT_EQ(count(grids, "<Grid Name=\"wall_contacts\" GridType=\"Uniform\">"), 1u);
  EXPECT_EQ(count(grids, "TopologyType=\"Polyline\" NumberOfElements=\"7\" NodesPerElement=\"2\""),
            1u);
  EXPECT_EQ(count(grids, "TopologyType=\"Polyline\" NumberOfElements=\"3\" NodesPerElement=\"2\""),
            1u);
  // The geometry is the two ends of each line: 2 M nodes.
  EXPECT_EQ(count(grids, "Dimensions=\"14 3\">p_000002.h5:/contacts/ends</DataItem>"), 1u);
  EXPECT_EQ(count(grids, "Dimensions=\"6 3\">p_000002.h5:/wall_contacts/ends</DataItem>"), 1u);
  // Every other dataset of one row per contact is a cell attribute.
  for (const char* name : {"point", "normal_force", "tangential_force"})
    EXPECT_EQ(count(grids, std::string("<Attribute Name=\"") + name +
                               "\" AttributeType=\"Vector\" Center=\"Cell\">"),
              2u)
        << name;
  for (const char* name : {"normal_force_magnitude", "overlap"})
    EXPECT_EQ(count(grids, std::string("<Attribute Name=\"") + name +
                               "\" AttributeType=\"Scalar\" Center=\"Cell\">"),
              2u)
        << name;
  EXPECT_EQ(count(grids, "Dimensions=\"7 3\">p_000002.h5:/contacts/normal_force</DataItem>"), 1u);
  EXPECT_EQ(count(grids, "Dimensions=\"3\">p_000002.h5:/wall_contacts/wall</DataItem>"), 1u);
  EXPECT_EQ(count(grids, "Dimensions=\"3\">p_000002.h5:/wall_contacts/id</DataItem>"), 1u);
  // The pairs' ids: one scalar per column of the M x 2 dataset, as HyperSlabs.
  for (const char* name : {"id_a", "id_b"})
    EXPECT_EQ(count(grids, std::string("<Attribute Name=\"") + name +
                               "\" AttributeType=\"Scalar\" Center=\"Cell\">"),
              1u)
        << name;
  EXPECT_EQ(count(grids, "<DataItem Dimensions=\"3 2\" Format=\"XML\">0 0 1 1 7 1</DataItem>"), 1u);
  EXPECT_EQ(count(grids, "<DataItem Dimensions=\"3 2\" Format=\"XML\">0 1 1 1 7 1</DataItem>"), 1u);
  EXPECT_EQ(count(grids, "Dimensions=\"7 2\">p_000002.h5:/contacts/id</DataItem>"), 2u);
  // Each line starts with the indent given.
  for (std::size_t at = 0; at < grids.size(); at = grids.find('\n', at) + 1)
    EXPECT_EQ(grids.compare(at, 4, "    "), 0) << grids.substr(at, 40);
}

TEST(XdmfContacts, EntryWithNetworkIsASpatialCollectionAtOneTime) {
  const std::string xml = render_xdmf({with_network(7, 3), with_network(0, 0)}, "p");
  EXPECT_EQ(count(xml, "GridType=\"Collection\" CollectionType=\"Spatial\""), 2u);
  EXPECT_EQ(count(xml, "<Time "), 2u);  // once per collection, for all its grids
  EXPECT_EQ(count(xml, "<Grid Name=\"particles\" GridType=\"Uniform\">"), 2u);
  EXPECT_EQ(count(xml, "TopologyType=\"Polyvertex\" NumberOfElements=\"30\""), 2u);
  // A group without contacts has no grid (ParaView cannot read a geometry of no nodes).
  EXPECT_EQ(count(xml, "NumberOfElements=\"0\""), 0u);
  EXPECT_EQ(count(xml, "<Grid Name=\"contacts\""), 1u);
  EXPECT_EQ(count(xml, "<Grid "), 1u + 4u + 2u);
  EXPECT_EQ(count(xml, "</Grid>"), count(xml, "<Grid "));
}

}  // namespace
}  // namespace grainflow
