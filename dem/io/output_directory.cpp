#include "dem/io/output_directory.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace grainflow {

namespace {

[[noreturn]] void fail(const std::string& dir, const std::string& what, const std::string& reason) {
  throw OutputError("output directory '" + dir + "': " + what + ": " + reason +
                    ". Choose another output directory or fix its permissions.");
}

// Unique per process and host, so that all ranks of a job (possibly on several nodes sharing a
// file system) can probe the same directory concurrently.
std::string probe_name() {
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) != 0) std::strcpy(host, "host");
  return ".grainflow_write_probe_" + std::string(host) + "_" + std::to_string(getpid());
}

}  // namespace

void prepare_output_directory(const std::string& dir) {
  namespace fs = std::filesystem;
  if (dir.empty()) fail(dir, "cannot use an empty path", "no directory given");

  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) fail(dir, "cannot create directory", ec.message());
  // create_directories succeeds without creating anything when the last component exists,
  // so a regular file of that name must be caught here.
  if (!fs::is_directory(dir, ec))
    fail(dir, "exists but is not a directory", ec ? ec.message() : "it is a regular file or other");

  const std::string probe = (fs::path(dir) / probe_name()).string();
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail(dir, "cannot create a file in it", std::strerror(errno));
  const char byte = '\n';
  const bool written = ::write(fd, &byte, 1) == 1;
  const int write_errno = errno;
  const bool closed = ::close(fd) == 0;
  const int close_errno = errno;
  const bool removed = ::unlink(probe.c_str()) == 0;
  const int unlink_errno = errno;
  if (!written) fail(dir, "cannot write to a file in it", std::strerror(write_errno));
  if (!closed) fail(dir, "cannot close a file in it", std::strerror(close_errno));
  if (!removed)
    fail(dir, "cannot remove the probe file '" + probe + "'", std::strerror(unlink_errno));
}

std::string no_space_note(const std::string& dir, std::uintmax_t bytes) {
  std::error_code ec;
  const std::filesystem::space_info space = std::filesystem::space(dir, ec);
  if (ec || space.available >= bytes) return "";
  return "No space left on device: " + std::to_string(space.available) +
         " bytes are free on the file system of '" + dir + "', the file needs about " +
         std::to_string(bytes);
}

}  // namespace grainflow
