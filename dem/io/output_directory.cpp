#include "dem/io/output_directory.hpp"

#include <fcntl.h>
#include <sys/file.h>
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
  // A dangling symbolic link: create_directories says only "File exists".
  fs::path link = fs::path(dir).lexically_normal();  // "out/": the link "out"
  if (link.filename().empty()) link = link.parent_path();
  if (fs::is_symlink(link, ec) && !fs::exists(link, ec))
    fail(dir, "is a symbolic link to '" + fs::read_symlink(link, ec).string() + "'",
         "that folder does not exist; create it");
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

OutputLock::OutputLock(MPI_Comm comm, const std::string& dir)
    : path_((std::filesystem::path(dir) / ".grain.lock").string()) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::string error;
  if (rank == 0) {
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ >= 0 && ::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const int why = errno;
      if (why == EWOULDBLOCK) {
        char holder[256] = {0};
        const ssize_t n = ::pread(fd_, holder, sizeof holder - 1, 0);
        std::string who(holder, n > 0 ? static_cast<std::size_t>(n) : 0);
        while (!who.empty() && (who.back() == '\n' || who.back() == ' ')) who.pop_back();
        const std::size_t space = who.find(' ');
        error = "output directory '" + dir + "' is in use by another running grain (" +
                (space == std::string::npos
                     ? std::string("a process")
                     : "process " + who.substr(0, space) + " on " + who.substr(space + 1)) +
                ", lock file '" + path_ +
                "'): two runs in one folder would write snapshots, log rows and checkpoints of "
                "the same names; wait for that run to end, or give this one another --output "
                "(or output.directory)";
      }
      ::close(fd_);  // another holder, or no flock on this file system: run unlocked
      fd_ = -1;
    } else if (fd_ >= 0) {
      char host[256] = {0};
      ::gethostname(host, sizeof host - 1);
      const std::string me = std::to_string(::getpid()) + " " + host + "\n";
      // Without the note the lock still holds; a refused second run then names no process.
      [[maybe_unused]] const bool noted =
          ::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, me.data(), me.size(), 0) >= 0;
    }
  }
  int length = static_cast<int>(error.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, comm);
  error.resize(static_cast<std::size_t>(length));
  MPI_Bcast(error.data(), length, MPI_CHAR, 0, comm);
  if (!error.empty()) throw OutputError(error);
}

OutputLock::~OutputLock() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // while still locked: a run waiting for it takes a fresh file
  ::close(fd_);
}

}  // namespace grainflow
