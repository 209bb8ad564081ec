#include "coupling/written_files.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace grainflow::coupling {

namespace fs = std::filesystem;

namespace {

constexpr std::uint64_t kFnvPrime = 0x100000001b3ULL;

std::string hex(std::uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
  return text;
}

// The record's entries: "<file relative to the folder>"  "fnv1a64 <16 hex digits>";
const std::regex& entry_pattern() {
  static const std::regex pattern(R"re(^"([^"]+)"[ ]+"fnv1a64 ([0-9a-f]{16})";$)re");
  return pattern;
}

// A name the record may hold: relative, inside the folder (a damaged name must not point
// anywhere else).
bool inside(const std::string& name) {
  const fs::path p(name);
  if (p.is_absolute() || name.empty()) return false;
  for (const fs::path& part : p)
    if (part == "..") return false;
  return true;
}

}  // namespace

std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t state) {
  for (const char c : bytes) {
    state ^= static_cast<unsigned char>(c);
    state *= kFnvPrime;
  }
  return state;
}

std::uint64_t file_checksum(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot be opened for reading");
  std::uint64_t state = kFnvOffsetBasis;
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    state = fnv1a64(std::string_view(buffer.data(), static_cast<std::size_t>(in.gcount())), state);
  }
  if (in.bad()) throw std::runtime_error(path + ": a read failed");
  return state;
}

int record_written_files(const std::string& folder, const std::string& who) {
  std::vector<std::string> names;
  std::error_code error;
  for (fs::recursive_directory_iterator it(folder, error), end; !error && it != end;
       it.increment(error)) {
    if (!it->is_regular_file()) continue;
    const std::string name = it->path().lexically_relative(folder).generic_string();
    if (name != kWrittenFilesRecord) names.push_back(name);
  }
  if (error)
    throw std::runtime_error(folder + ": cannot list the written files (" + error.message() + ")");
  std::sort(names.begin(), names.end());

  std::ostringstream text;
  text << "/*--------------------------------*- C++ -*----------------------------------*\\\n"
       << "  grainflow: the files grainFoam wrote in this time folder (" << who << "),\n"
       << "  each with its FNV-1a 64-bit checksum. A restart from this folder stops when a\n"
       << "  file differs. After a change made on purpose (setFields, an edited boundary\n"
       << "  condition), delete that file's line.\n"
       << "\\*---------------------------------------------------------------------------*/\n"
       << "FoamFile\n{\n    version     2.0;\n    format      ascii;\n"
       << "    class       dictionary;\n    object      " << kWrittenFilesRecord << ";\n}\n\n";
  for (const std::string& name : names)
    text << '"' << name << "\"  \"fnv1a64 " << hex(file_checksum(folder + "/" + name)) << "\";\n";

  // Written whole, then renamed: a run stopped mid-write leaves no half record.
  const std::string path = folder + "/" + kWrittenFilesRecord, partial = path + ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out << text.str();
    out.close();
    if (!out) throw std::runtime_error(partial + ": cannot be written");
  }
  fs::rename(partial, path, error);
  if (error) throw std::runtime_error(path + ": cannot be written (" + error.message() + ")");
  return static_cast<int>(names.size());
}

WrittenFilesCheck check_written_files(const std::string& folder) {
  WrittenFilesCheck check;
  const std::string record = folder + "/" + kWrittenFilesRecord;
  std::ifstream in(record, std::ios::binary);
  if (!in) return check;
  check.recorded = true;

  const std::string advice =
      "A damaged file would restart another run without a word. If you changed it on purpose "
      "(setFields, mapFields, an edited boundary condition), delete its line from " +
      record +
      " and start again; otherwise restart from an earlier time folder (or from 0) that "
      "is intact.";
  // Not "delete its line": without the time's own uniform/time and uniform/grainflowCheckpoint
  // the fluid would go on from this time while the DEM started again from the scene.
  const std::string position_advice =
      "uniform/time and uniform/grainflowCheckpoint say where the fluid and the DEM stand at "
      "this time (the time index, the DEM checkpoint); a restart cannot do without them as "
      "written, and they cannot be remade by hand. Restart from another time folder that is "
      "intact (startFrom startTime; startTime <time> in system/controlDict), or start afresh "
      "from time 0.";
  std::ostringstream problems;
  int bad = 0;
  bool positionBad = false;  // uniform/time or uniform/grainflowCheckpoint among them
  std::string line;
  int number = 0;
  bool entries = false;  // past the FoamFile header's closing brace
  while (std::getline(in, line)) {
    ++number;
    if (!entries) {
      entries = line == "}";
      continue;
    }
    if (line.empty()) continue;
    std::smatch match;
    if (!std::regex_match(line, match, entry_pattern()) || !inside(match[1].str())) {
      check.problem = "grainFoam: error: line " + std::to_string(number) + " of " + record +
                      " is not an entry `\"<file>\"  \"fnv1a64 <16 hex digits>\";`: the record "
                      "of the files written at this time is damaged, so they cannot be "
                      "checked. Delete " +
                      record + " to restart from them unchecked, or restart from another time.";
      return check;
    }
    const std::string name = match[1].str(), path = folder + "/" + name;
    // uniform/time and uniform/grainflowCheckpoint say where the fluid and the DEM stand.
    const bool position = name == "uniform/time" || name == "uniform/grainflowCheckpoint";
    if (!fs::is_regular_file(path)) {
      ++bad;
      positionBad = positionBad || position;
      problems << "  " << path << " is missing (line " << number << " of the record)\n";
      continue;
    }
    std::uint64_t now = 0;
    try {
      now = file_checksum(path);
    } catch (const std::exception& e) {
      ++bad;
      positionBad = positionBad || position;
      problems << "  " << e.what() << '\n';
      continue;
    }
    if (hex(now) != match[2].str()) {
      ++bad;
      positionBad = positionBad || position;
      problems << "  " << path << ": FNV-1a checksum " << hex(now) << ", recorded "
               << match[2].str() << " (line " << number << ")\n";
      continue;
    }
    ++check.checked;
  }
  if (!entries) {
    check.problem = "grainFoam: error: " + record +
                    " has no FoamFile header ending in a line `}`: the record of the files "
                    "written at this time is damaged, so they cannot be checked. Delete it to "
                    "restart from them unchecked, or restart from another time.";
    return check;
  }
  if (bad > 0)
    check.problem = "grainFoam: error: " + std::to_string(bad) +
                    (bad == 1 ? " file of time folder " : " files of time folder ") +
                    fs::path(folder).filename().string() + (bad == 1 ? " differs" : " differ") +
                    " from what grainFoam wrote there (its record " + record + "):\n" +
                    problems.str() + (positionBad ? position_advice : advice);
  return check;
}

}  // namespace grainflow::coupling
