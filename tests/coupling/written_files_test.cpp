// The record of the files written at a time (coupling/written_files.hpp): FNV-1a against its
// published test vectors, every single-bit flip seen, and the record's check of changed,
// missing and unlisted files and of a damaged record. grainFoam's use of it is tested end to
// end by coupling.restart_files.
#include "coupling/written_files.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace {

namespace fs = std::filesystem;
using grainflow::coupling::check_written_files;
using grainflow::coupling::file_checksum;
using grainflow::coupling::fnv1a64;
using grainflow::coupling::record_written_files;

void write(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

std::string read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

class WrittenFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() /
              ("grainflow_written_files_" + std::to_string(::getpid()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(folder_);
    write(folder_ / "U", "FoamFile{}\ninternalField uniform (1 2 3);\n");
    write(folder_ / "p", std::string("binary\0\x01\x02", 9));
    write(folder_ / "uniform" / "time", "value 0.02;\n");
  }
  void TearDown() override { fs::remove_all(folder_); }
  fs::path folder_;
};

// The FNV reference vectors (Fowler, Noll & Vo, http://www.isthe.com/chongo/tech/comp/fnv/,
// test suite of FNV-1a 64-bit).
TEST(Fnv1a64, MatchesThePublishedVectors) {
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ULL);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(fnv1a64("foobar"), 0x85944171f73967e8ULL);
  // Continued in pieces as a file is read in blocks.
  EXPECT_EQ(fnv1a64("bar", fnv1a64("foo")), fnv1a64("foobar"));
}

// Every change within one byte changes the checksum (each step is a bijection of the state):
// all 8 x 256 single-bit flips of a random 256-byte block.
TEST(Fnv1a64, SeesEverySingleBitFlip) {
  std::mt19937 random(7);
  std::string block(256, '\0');
  for (char& c : block) c = static_cast<char>(random() & 0xff);
  const std::uint64_t intact = fnv1a64(block);
  int seen = 0;
  for (std::size_t i = 0; i < block.size(); ++i)
    for (int bit = 0; bit < 8; ++bit) {
      std::string flipped = block;
      flipped[i] = static_cast<char>(flipped[i] ^ (1 << bit));
      seen += fnv1a64(flipped) != intact;
    }
  EXPECT_EQ(seen, 8 * 256);
}

TEST_F(WrittenFiles, IntactFilesMatch) {
  EXPECT_EQ(record_written_files(folder_.string(), "1 rank, time 0.02"), 3);
  EXPECT_EQ(file_checksum((folder_ / "U").string()), fnv1a64(read(folder_ / "U")));
  // A file a post-processing utility adds later is not checked.
  write(folder_ / "vorticity", "new");
  const auto check = check_written_files(folder_.string());
  EXPECT_TRUE(check.recorded);
  EXPECT_EQ(check.checked, 3);
  EXPECT_EQ(check.problem, "");
}

TEST_F(WrittenFiles, NoRecordIsNotChecked) {
  const auto check = check_written_files(folder_.string());
  EXPECT_FALSE(check.recorded);
  EXPECT_EQ(check.checked, 0);
  EXPECT_EQ(check.problem, "");
}

TEST_F(WrittenFiles, NamesAChangedAndAMissingFile) {
  record_written_files(folder_.string(), "1 rank, time 0.02");
  write(folder_ / "uniform" / "time", "value 0.03;\n");
  fs::remove(folder_ / "p");
  const auto check = check_written_files(folder_.string());
  EXPECT_EQ(check.checked, 1);
  EXPECT_NE(check.problem.find("2 files of time folder " + folder_.filename().string() + " differ"),
            std::string::npos)
      << check.problem;
  EXPECT_NE(check.problem.find((folder_ / "uniform" / "time").string() + ": FNV-1a checksum " +
                               "8db18155bcbae8f0"),
            std::string::npos)
      << check.problem;  // fnv1a64("value 0.03;\n"), the file as it now is
  EXPECT_EQ(fnv1a64("value 0.03;\n"), 0x8db18155bcbae8f0ULL);
  EXPECT_NE(check.problem.find((folder_ / "p").string() + " is missing"), std::string::npos)
      << check.problem;
}

// The advice of the message: deleting a changed file's line accepts the change.
TEST_F(WrittenFiles, ADeletedLineAcceptsAChange) {
  record_written_files(folder_.string(), "1 rank, time 0.02");
  write(folder_ / "U", "FoamFile{}\ninternalField uniform (1 2 4);\n");
  const fs::path record = folder_ / grainflow::coupling::kWrittenFilesRecord;
  std::string text = read(record);
  const auto line = text.find("\"U\"");
  ASSERT_NE(line, std::string::npos);
  text.erase(line, text.find('\n', line) + 1 - line);
  write(record, text);
  const auto check = check_written_files(folder_.string());
  EXPECT_EQ(check.checked, 2);
  EXPECT_EQ(check.problem, "");
}

// A damaged record is refused, whatever the damage: a garbled entry, a name that leaves the
// folder, a lost header.
TEST_F(WrittenFiles, RefusesADamagedRecord) {
  record_written_files(folder_.string(), "1 rank, time 0.02");
  const fs::path record = folder_ / grainflow::coupling::kWrittenFilesRecord;
  const std::string intact = read(record);
  for (const std::string& line : {std::string("\"U\"  \"fnv1a64 12345\";"),
                                  std::string("\"../U\"  \"fnv1a64 0123456789abcdef\";"),
                                  std::string("\"U\" \"fnv1a64 0123456789abcdef\"")}) {
    write(record, intact + line + "\n");
    const auto check = check_written_files(folder_.string());
    EXPECT_NE(check.problem.find("is not an entry"), std::string::npos) << line;
    EXPECT_NE(check.problem.find(record.string()), std::string::npos) << line;
  }
  std::string headless = intact;
  headless.replace(headless.find("\n}\n"), 3, "\n]\n");
  write(record, headless);
  EXPECT_NE(check_written_files(folder_.string()).problem.find("has no FoamFile header"),
            std::string::npos);
}

}  // namespace
