// LogTable: the CSV header and every row read back to exactly the numbers written.
// Reference: the LogRow values themselves; tolerance 0, because doubles are printed with 17
// significant digits, which always round-trip through strtod (IEEE 754 binary64, C11 7.21.6.1).
#include "dem/io/log_table.hpp"

#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "dem/io/output_directory.hpp"

namespace grainflow {
namespace {

namespace fs = std::filesystem;


fs::path fresh_directory(const std::string& name) {
  const fs::path dir = fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "log_table_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string cell;
  while (std::getline(s, cell, ',')) out.push_back(cell);
  return out;
}

std::vector<std::string> read_lines(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

LogRow awkward_row(int i) {
  // Values whose decimal expansions need all 17 digits, extremes of range, and large counts.
  return LogRow{.time = 0.1 * i + 1.0 / 3.0,
                .step = 1'234'567'890'123L + i,
                .particles = 2'000'000'000L + i,
                .kinetic_translational = std::numbers::pi * 1e-7 * (i + 1),
                .kinetic_rotational = i == 0 ? 0.0 : std::numeric_limits<double>::denorm_min() * i,
                .max_overlap_ratio = std::nextafter(0.01, 1.0),
                .contacts = 123456L * i,
                .rebuilds = i,
                .removed = 0,
                .wall_seconds = std::numeric_limits<double>::max() / (i + 1)};
}

TEST(LogTable, HeaderNamesColumnsWithUnits) {
  const fs::path path = fresh_directory("header") / "log.csv";
  { LogTable log(MPI_COMM_WORLD, path.string()); }
  const std::vector<std::string> lines = read_lines(path);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0],
            "time_s,step,particles,ke_trans_J,ke_rot_J,max_overlap_ratio,contacts,rebuilds,"
            "removed,wall_s");
}

TEST(LogTable, RowsRoundTripExactly) {
  const fs::path path = fresh_directory("rows") / "log.csv";
  const int n = 5;
  {
    LogTable log(MPI_COMM_WORLD, path.string());
    for (int i = 0; i < n; ++i) log.write(awkward_row(i));
  }
  const std::vector<std::string> lines = read_lines(path);
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(n + 1));
  const std::vector<std::string> header = split(lines[0]);
  ASSERT_EQ(header.size(), 10u);
  for (int i = 0; i < n; ++i) {
    SCOPED_TRACE(lines[static_cast<std::size_t>(i + 1)]);
    const std::vector<std::string> c = split(lines[static_cast<std::size_t>(i + 1)]);
    ASSERT_EQ(c.size(), header.size());
    const LogRow r = awkward_row(i);
    const auto d = [&](int k) {
      return std::strtod(c[static_cast<std::size_t>(k)].c_str(), nullptr);
    };
    const auto l = [&](int k) {
      return std::strtol(c[static_cast<std::size_t>(k)].c_str(), nullptr, 10);
    };
    EXPECT_EQ(d(0), r.time);
    EXPECT_EQ(l(1), r.step);
    EXPECT_EQ(l(2), r.particles);
    EXPECT_EQ(d(3), r.kinetic_translational);
    EXPECT_EQ(d(4), r.kinetic_rotational);
    EXPECT_EQ(d(5), r.max_overlap_ratio);
    EXPECT_EQ(l(6), r.contacts);
    EXPECT_EQ(l(7), r.rebuilds);
    EXPECT_EQ(l(8), r.removed);
    EXPECT_EQ(d(9), r.wall_seconds);
  }
}

// Each row is flushed: a run killed after write() has the row on disk.
TEST(LogTable, RowIsOnDiskBeforeTheTableCloses) {
  const fs::path path = fresh_directory("flush") / "log.csv";
  LogTable log(MPI_COMM_WORLD, path.string());
  log.write(awkward_row(1));
  EXPECT_EQ(read_lines(path).size(), 2u);
  log.write(awkward_row(2));
  EXPECT_EQ(read_lines(path).size(), 3u);
}

TEST(LogTable, UnwritablePathThrowsNamingIt) {
  const fs::path base = fresh_directory("unwritable");
  std::ofstream(base / "plain_file") << "x";
  const std::string path = (base / "plain_file" / "log.csv").string();
  try {
    LogTable log(MPI_COMM_WORLD, path);
    ADD_FAILURE() << "no OutputError";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

// The tutorial helper plots chosen columns of a table like this one to a PNG.
TEST(LogTable, PlotScriptWritesPng) {
  // The Python that has matplotlib and numpy (scripts/python.sh).
  const std::string python = GRAINFLOW_SOURCE_DIR "/scripts/python.sh";
  const fs::path dir = fresh_directory("plot");
  {
    LogTable log(MPI_COMM_WORLD, (dir / "log.csv").string());
    for (int i = 0; i < 20; ++i) {
      LogRow r = awkward_row(i);
      r.wall_seconds = 0.5 * i;
      log.write(r);
    }
  }
  const fs::path png = dir / "energy.png";
  const std::string command = python + " " GRAINFLOW_SOURCE_DIR "/scripts/plot_log.py " +
                              (dir / "log.csv").string() + " -c ke_trans_J contacts -o " +
                              png.string() + " > " + (dir / "out.txt").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << read_lines(dir / "out.txt").front();
  ASSERT_TRUE(fs::exists(png));
  std::ifstream in(png, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");

  // An unknown column is an error that lists the valid names.
  const std::string bad = python + " " GRAINFLOW_SOURCE_DIR "/scripts/plot_log.py " +
                          (dir / "log.csv").string() + " -c ke_total -o " + png.string() + " > " +
                          (dir / "bad.txt").string() + " 2>&1";
  EXPECT_NE(std::system(bad.c_str()), 0);
  const std::vector<std::string> lines = read_lines(dir / "bad.txt");
  ASSERT_FALSE(lines.empty());
  EXPECT_NE(lines.back().find("valid columns: time_s,"), std::string::npos) << lines.back();
}

// A restarted run continues the table after the checkpoint's step. A last row without its
// newline was cut short (kill -9, or a short write on a full disk): even its step may be cut
// ("12" of step 1234), so it is dropped although 12 <= the checkpoint's step.
TEST(LogTable, ContinuingDropsARowCutShort) {
  const fs::path path = fresh_directory("cut_row") / "log.csv";
  {
    std::ofstream out(path);
    out << LogTable::header << "\n0.1,10,5,0,0,0,0,1,0,0.5\n0.2,20,5,0,0,0,0,2,0,1.0\n0.3,12";
  }
  { LogTable log(MPI_COMM_WORLD, path.string(), 100); }
  const std::vector<std::string> lines = read_lines(path);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[2], "0.2,20,5,0,0,0,0,2,0,1.0");
}

// The copy a checkpoint keeps (record()) holds the header and the recorded rows, each exactly
// as the file has it; a row written with `recorded` false is in the file only. A restart with
// that copy makes the file the copy, whatever the folder held: here another run's log whose
// steps are all below the checkpoint's (kept whole by the step rule alone), with a note.
TEST(LogTable, RestartTakesTheCheckpointsCopy) {
  const fs::path dir = fresh_directory("record");
  const fs::path path = dir / "log.csv";
  std::string copy;
  {
    LogTable log(MPI_COMM_WORLD, path.string());
    log.write(awkward_row(0));
    log.write(awkward_row(1));
    copy = log.record();
    log.write(awkward_row(2), /*recorded=*/false);
    EXPECT_EQ(log.record(), copy);
  }
  std::ifstream in(path);
  const std::string file{std::istreambuf_iterator<char>(in), {}};
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) {
    EXPECT_EQ(read_lines(path).size(), 4u);
    EXPECT_TRUE(file.starts_with(copy)) << copy;
    EXPECT_EQ(std::count(copy.begin(), copy.end(), '\n'), 3);
  }
  {  // the stopped run's own file: continued from the copy, the unrecorded row dropped
    LogTable log(MPI_COMM_WORLD, path.string(), awkward_row(2).step, {}, copy);
    if (rank == 0) {
      EXPECT_EQ(log.note(), "");
    }
  }
  if (rank == 0) {
    EXPECT_EQ(read_lines(path).size(), 3u);
  }
  {
    std::ofstream out(path);
    out << LogTable::header << "\n0.1,10,5,0,0,0,0,1,0,0.5\n";
  }
  {
    LogTable log(MPI_COMM_WORLD, path.string(), awkward_row(1).step, {}, copy);
    if (rank == 0) {
      EXPECT_NE(log.note().find("held rows that the checkpoint's run did not write"),
                std::string::npos)
          << log.note();
      EXPECT_NE(log.note().find("2 row(s), up to step " + std::to_string(awkward_row(1).step)),
                std::string::npos)
          << log.note();
    }
  }
  if (rank == 0) {
    std::ifstream again(path);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(again), {}), copy);
  }
  fs::remove(path);
  {
    LogTable log(MPI_COMM_WORLD, path.string(), awkward_row(1).step, {}, copy);
    if (rank == 0) {
      EXPECT_NE(log.note().find("was missing: restored"), std::string::npos);
    }
  }
  if (rank == 0) {
    EXPECT_EQ(read_lines(path).size(), 3u);
  }
  // Beyond its limit the copy is dropped (empty: checkpoints keep none), the file goes on.
  {
    LogTable log(MPI_COMM_WORLD, path.string());
    log.set_record_limit(log.record().size() + 400);  // room for a row or two
    for (int i = 0; i < 100; ++i) log.write(awkward_row(i));
    EXPECT_EQ(log.record(), "");
  }
  if (rank == 0) {
    EXPECT_EQ(read_lines(path).size(), 101u);
  }
}

}  // namespace
}  // namespace grainflow
