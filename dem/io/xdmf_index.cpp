#include "dem/io/xdmf_index.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string_view>

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

void data_item(std::string& out, const XdmfEntry& e, const SnapshotField& f, const char* indent) {
  out += indent;
  out += "<DataItem Format=\"HDF\" NumberType=\"";
  out += number_type(f.type);
  out += "\" Precision=\"";
  out += std::to_string(precision(f.type));
  out += "\" Dimensions=\"";
  out += std::to_string(e.count);
  if (f.components != 1) {
    out += ' ';
    out += std::to_string(f.components);
  }
  out += "\">";
  out += xml_escape(e.file);
  out += ":/";
  out += f.name;
  out += "</DataItem>\n";
}

[[noreturn]] void fail(const std::string& path, const std::string& what, int err) {
  throw OutputError("cannot write '" + path + "': " + what + ": " + std::strerror(err) +
                    ". Check free space and permissions of the output directory.");
}

}  // namespace

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
  out += "      <Grid Name=\"" + xml_escape(stem) + "\" GridType=\"Uniform\">\n";
  out += "        <Time Value=\"" + exact(e.time) + "\"/>\n";
  out += "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" +
         std::to_string(e.count) + "\" NodesPerElement=\"1\"/>\n";
  for (const SnapshotField& f : snapshot_fields) {
    if (std::string_view(f.name) != snapshot_geometry_field) continue;
    out += "        <Geometry GeometryType=\"XYZ\">\n";
    data_item(out, e, f, "          ");
    out += "        </Geometry>\n";
  }
  for (std::size_t k = 0; k < snapshot_fields.size(); ++k) {
    const SnapshotField& f = snapshot_fields[k];
    if (std::string_view(f.name) == snapshot_geometry_field) continue;
    if (!(e.fields & (SnapshotFieldSet{1} << k))) continue;
    out += "        <Attribute Name=\"" + std::string(f.name) + "\" AttributeType=\"" +
           (f.components == 1 ? "Scalar" : "Vector") + "\" Center=\"Node\">\n";
    data_item(out, e, f, "          ");
    out += "        </Attribute>\n";
  }
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
