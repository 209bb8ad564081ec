#include "dem/io/xdmf_index.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string_view>

#include "dem/io/contact_network.hpp"
#include "dem/io/output_directory.hpp"

namespace grainflow {

namespace {

std::string xml_escape(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// Shortest text that reads back to the same double (17 significant digits always suffice).
std::string exact(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

const char* number_type(SnapshotField::Type t) {
  return t == SnapshotField::Type::Float64 ? "Float" : "Int";
}

int precision(SnapshotField::Type t) { return t == SnapshotField::Type::Int32 ? 4 : 8; }

// A DataItem of `count` rows of field f in `file`; `group`: the dataset's group (nullptr: the
// root).
void data_item(std::string& out, const std::string& file, long count, const SnapshotField& f,
               const char* indent, const char* group = nullptr) {
  out += indent;
  out += "<DataItem Format=\"HDF\" NumberType=\"";
  out += number_type(f.type);
  out += "\" Precision=\"";
  out += std::to_string(precision(f.type));
  out += "\" Dimensions=\"";
  out += std::to_string(count);
  if (f.components != 1) {
    out += ' ';
    out += std::to_string(f.components);
  }
  out += "\">";
  out += xml_escape(file);
  out += ":/";
  if (group) {
    out += group;
    out += '/';
  }
  out += f.name;
  out += "</DataItem>\n";
}

[[noreturn]] void fail(const std::string& path, const std::string& what, int err) {
  throw OutputError("cannot write '" + path + "': " + what + ": " + std::strerror(err) +
                    ". Check free space and permissions of the output directory.");
}

// One group of the contact network as a Polyline grid: the `ends` dataset is the geometry,
// two nodes per contact, and lines need no connectivity DataItem (Xdmf2 gives a topology
// without one the default connectivity 0..2M-1, i.e. nodes 2k and 2k+1 for line k).
// An empty group has no grid: ParaView's XDMF reader fails on a geometry of no nodes (and
// then leaves an empty block).
template <std::size_t N>
void contact_grid(std::string& out, const XdmfEntry& e, const char* group, long count,
                  const std::array<ContactField, N>& fields, const std::string& indent) {
  if (count <= 0) return;
  const std::string in = indent + "  ", item = indent + "    ";
  out += indent + "<Grid Name=\"" + group + "\" GridType=\"Uniform\">\n";
  out += in + "<Topology TopologyType=\"Polyline\" NumberOfElements=\"" + std::to_string(count) +
         "\" NodesPerElement=\"2\"/>\n";
  for (const ContactField& c : fields) {
    if (c.rows != 2) continue;
    out += in + "<Geometry GeometryType=\"XYZ\">\n";
    data_item(out, e.file, 2 * count, c.field, item.c_str(), group);
    out += in + "</Geometry>\n";
  }
  for (const ContactField& c : fields) {
    if (c.rows != 1) continue;  // the line ends: the geometry
    if (c.field.components == 2) {
      // The pairs' ids (M x 2): one scalar per column, "id_a" and "id_b", each a HyperSlab
      // (start, stride, count per dimension) of the dataset.
      for (int column = 0; column < 2; ++column) {
        out += in + "<Attribute Name=\"" + c.field.name + (column == 0 ? "_a" : "_b") +
               "\" AttributeType=\"Scalar\" Center=\"Cell\">\n";
        out += item + "<DataItem ItemType=\"HyperSlab\" Dimensions=\"" + std::to_string(count) +
               " 1\" Type=\"HyperSlab\">\n";
        out += item + "  <DataItem Dimensions=\"3 2\" Format=\"XML\">0 " + std::to_string(column) +
               " 1 1 " + std::to_string(count) + " 1</DataItem>\n";
        data_item(out, e.file, count, c.field, (item + "  ").c_str(), group);
        out += item + "</DataItem>\n";
        out += in + "</Attribute>\n";
      }
      continue;
    }
    out += in + "<Attribute Name=\"" + c.field.name + "\" AttributeType=\"" +
           (c.field.components == 1 ? "Scalar" : "Vector") + "\" Center=\"Cell\">\n";
    data_item(out, e.file, count, c.field, item.c_str(), group);
    out += in + "</Attribute>\n";
  }
  out += indent + "</Grid>\n";
}

}  // namespace

std::string render_contact_grids(const XdmfEntry& e, const std::string& indent) {
  std::string out;
  if (e.contacts < 0) return out;
  contact_grid(out, e, pair_contact_group, e.contacts, pair_contact_fields, indent);
  contact_grid(out, e, wall_contact_group, e.wall_contacts, wall_contact_fields, indent);
  return out;
}

std::string render_xdmf_head(const std::string& series_name) {
  std::string out;
  out += "<?xml version=\"1.0\" ?>\n";
  out += "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n";
  out += "<Xdmf Version=\"2.0\">\n";
  out += "  <Domain>\n";
  out += "    <Grid Name=\"" + xml_escape(series_name) +
         "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  return out;
}

std::string render_xdmf_entry(const XdmfEntry& e) {
  std::string out;
  out.reserve(2048);
  const std::string stem = std::filesystem::path(e.file).stem().string();
  // Every time step is a Spatial collection: the particles' grid (none when the snapshot holds
  // no particle) and, with a contact network, the network's grids. ParaView's XDMF 2 reader
  // fails on a geometry of no points, and it expects every time step to be of the first one's
  // type, so an empty snapshot (a stream-filled scene at t = 0, a run its particles have all
  // left) can only be an empty collection among collections.
  out += "      <Grid Name=\"" + xml_escape(stem) +
         "\" GridType=\"Collection\" CollectionType=\"Spatial\">\n";
  out += "        <Time Value=\"" + exact(e.time) + "\"/>\n";
  if (e.count > 0) {
    const std::string in = "          ";  // the grid's children
    const std::string item_indent = in + "  ";
    out += "        <Grid Name=\"particles\" GridType=\"Uniform\">\n";
    out += in + "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" +
           std::to_string(e.count) + "\" NodesPerElement=\"1\"/>\n";
    for (const SnapshotField& f : snapshot_fields) {
      if (std::string_view(f.name) != snapshot_geometry_field) continue;
      out += in + "<Geometry GeometryType=\"XYZ\">\n";
      data_item(out, e.file, e.count, f, item_indent.c_str());
      out += in + "</Geometry>\n";
    }
    for (std::size_t k = 0; k < snapshot_fields.size(); ++k) {
      const SnapshotField& f = snapshot_fields[k];
      if (std::string_view(f.name) == snapshot_geometry_field) continue;
      if (!(e.fields & (SnapshotFieldSet{1} << k))) continue;
      out += in + "<Attribute Name=\"" + std::string(f.name) + "\" AttributeType=\"" +
             (f.components == 1 ? "Scalar" : "Vector") + "\" Center=\"Node\">\n";
      data_item(out, e.file, e.count, f, item_indent.c_str());
      out += in + "</Attribute>\n";
    }
    out += "        </Grid>\n";
  }
  out += render_contact_grids(e, "        ");
  out += "      </Grid>\n";
  return out;
}

std::string render_xdmf_tail() { return "    </Grid>\n  </Domain>\n</Xdmf>\n"; }

std::string render_xdmf(const std::vector<XdmfEntry>& entries, const std::string& series_name) {
  std::string out = render_xdmf_head(series_name);
  for (const XdmfEntry& e : entries) out += render_xdmf_entry(e);
  out += render_xdmf_tail();
  return out;
}

void write_file_atomically(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail(path, "cannot create temporary file '" + tmp + "'", errno);
  std::size_t done = 0;
  while (done < content.size()) {
    const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      fail(path, "cannot write temporary file '" + tmp + "'", err);
    }
    done += static_cast<std::size_t>(n);
  }
  // Without fsync a crash right after the rename can leave an empty file under the final name
  // on some file systems (ext4 delayed allocation), which defeats the point of the rename.
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    fail(path, "cannot flush temporary file '" + tmp + "'", err);
  }
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail(path, "cannot close temporary file '" + tmp + "'", err);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail(path, "cannot rename '" + tmp + "' over it", err);
  }
}

}  // namespace grainflow
