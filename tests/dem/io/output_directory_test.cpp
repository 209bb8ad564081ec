// prepare_output_directory: creates nested directories, and reports unusable paths with an
// OutputError whose message names the path. Reference: POSIX behaviour (mkdir under a regular
// file fails with ENOTDIR, as root too); no numerical tolerance involved.
#include "dem/io/output_directory.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <string>

namespace grainflow {
namespace {

namespace fs = std::filesystem;

fs::path fresh_directory(const std::string& name) {
  const fs::path dir =
      fs::path(GRAINFLOW_BINARY_DIR) / "test_output" / "output_directory_test" / name;
  fs::remove_all(dir);
  return dir;
}

// The message of the OutputError thrown for `dir`, or "" if none was thrown.
std::string error_for(const std::string& dir) {
  try {
    prepare_output_directory(dir);
  } catch (const OutputError& e) {
    return e.what();
  }
  return "";
}

TEST(OutputDirectory, CreatesNestedDirectories) {
  const fs::path base = fresh_directory("nested");
  const fs::path dir = base / "a" / "b" / "c";
  ASSERT_NO_THROW(prepare_output_directory(dir.string()));
  EXPECT_TRUE(fs::is_directory(dir));
  // The probe file is gone: the directory is left empty.
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(OutputDirectory, ExistingDirectoryIsAccepted) {
  const fs::path dir = fresh_directory("existing");
  fs::create_directories(dir);
  std::ofstream(dir / "keep.txt") << "user data\n";
  ASSERT_NO_THROW(prepare_output_directory(dir.string()));
  EXPECT_TRUE(fs::exists(dir / "keep.txt"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(OutputDirectory, PathUnderRegularFileNamesPathAndReason) {
  const fs::path base = fresh_directory("under_file");
  fs::create_directories(base);
  const fs::path file = base / "plain_file";
  std::ofstream(file) << "x";
  const std::string dir = (file / "x" / "y").string();
  const std::string message = error_for(dir);
  ASSERT_FALSE(message.empty()) << "no OutputError for " << dir;
  EXPECT_NE(message.find(dir), std::string::npos) << message;
  EXPECT_NE(message.find("Not a directory"), std::string::npos) << message;
}

TEST(OutputDirectory, SystemFileAsParentIsRejected) {
  // The brief's example; /etc/hostname exists on Debian images, skip where it does not.
  if (!fs::is_regular_file("/etc/hostname")) GTEST_SKIP() << "/etc/hostname is not a file here";
  const std::string message = error_for("/etc/hostname/x");
  EXPECT_NE(message.find("/etc/hostname/x"), std::string::npos) << message;
}

TEST(OutputDirectory, RegularFileItselfIsRejected) {
  const fs::path base = fresh_directory("is_file");
  fs::create_directories(base);
  const fs::path file = base / "results";
  std::ofstream(file) << "x";
  const std::string message = error_for(file.string());
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
  // libstdc++'s create_directories itself reports ENOTDIR ("Not a directory"); other standard
  // libraries succeed silently and the explicit check says "is not a directory".
  std::string lower = message;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  EXPECT_NE(lower.find("not a directory"), std::string::npos) << message;
}

// A symbolic link to a folder that does not exist: named with its target (create_directories
// says only "File exists"), and nothing is created.
TEST(OutputDirectory, DanglingSymbolicLinkNamesItsTarget) {
  const fs::path base = fresh_directory("dangling_link");
  fs::create_directories(base);
  const fs::path link = base / "out", target = base / "gone";
  fs::create_directory_symlink(target, link);
  const std::string message = error_for(link.string());
  EXPECT_NE(
      message.find("is a symbolic link to '" + target.string() + "': that folder does not exist"),
      std::string::npos)
      << message;
  EXPECT_NE(error_for(link.string() + "/").find("is a symbolic link to"), std::string::npos);
  EXPECT_FALSE(fs::exists(target));
}

TEST(OutputDirectory, ReadOnlyDirectoryIsRejected) {
  if (::geteuid() == 0) GTEST_SKIP() << "root bypasses permission bits";
  const fs::path dir = fresh_directory("read_only");
  fs::create_directories(dir);
  fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
  const std::string message = error_for(dir.string());
  fs::permissions(dir, fs::perms::owner_all);
  EXPECT_NE(message.find(dir.string()), std::string::npos) << message;
  EXPECT_NE(message.find("Permission denied"), std::string::npos) << message;
}

TEST(OutputDirectory, EmptyPathIsRejected) {
  EXPECT_THROW(prepare_output_directory(""), OutputError);
}

}  // namespace
}  // namespace grainflow
