#include "dem/io/direct_write_driver.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>

namespace grainflow {
namespace {

constexpr haddr_t kBlock = 4096;                // offset, length and memory alignment
constexpr std::size_t kBounceBytes = 1u << 20;  // the aligned copy a direct write goes from
constexpr haddr_t kMaxAddr = std::numeric_limits<off_t>::max();

std::atomic<long long> direct_bytes{0};

// One open file. `pub` first: HDF5 holds a pointer to it, which is a pointer to the whole.
struct DirectFile {
  H5FD_t pub;
  int fd = -1;         // every read, every small write, the ends of large ones
  int direct_fd = -1;  // the O_DIRECT descriptor; -1 when the file system refuses it
  haddr_t eoa = 0;     // end of the address space HDF5 has allocated
  haddr_t eof = 0;     // end of the file's bytes
  dev_t device = 0;
  ino_t inode = 0;
  void* bounce = nullptr;
};

DirectFile* as_file(H5FD_t* f) { return reinterpret_cast<DirectFile*>(f); }
const DirectFile* as_file(const H5FD_t* f) { return reinterpret_cast<const DirectFile*>(f); }

// An entry on HDF5's error stack in the POSIX driver's form ("errno = 28, error message =
// '...'"), which hdf5_reason() turns into the system's text.
herr_t fail(const char* function, hid_t minor, const char* what, int err) {
  H5Epush2(H5E_DEFAULT, __FILE__, function, __LINE__, H5E_ERR_CLS, H5E_VFL, minor,
           "%s, errno = %d, error message = '%s'", what, err, std::strerror(err));
  return -1;
}

bool write_all(int fd, const unsigned char* p, std::size_t size, haddr_t at) {
  while (size > 0) {
    const ssize_t n = pwrite(fd, p, size, static_cast<off_t>(at));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = EIO;
      return false;
    }
    p += n;
    at += static_cast<haddr_t>(n);
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

void close_direct(DirectFile& f) {
  if (f.direct_fd >= 0) close(f.direct_fd);
  f.direct_fd = -1;
}

// The whole blocks [first, last) of a write starting at `addr` from `buf`, through the bounce
// buffer. False with errno on failure; a file system that turns out to refuse O_DIRECT
// (EINVAL) gets the rest buffered instead.
bool write_direct(DirectFile& f, const unsigned char* buf, haddr_t addr, haddr_t first,
                  haddr_t last) {
  if (!f.bounce) f.bounce = std::aligned_alloc(kBlock, kBounceBytes);
  haddr_t at = first;
  while (at < last && f.bounce && f.direct_fd >= 0) {
    const std::size_t n = static_cast<std::size_t>(std::min<haddr_t>(last - at, kBounceBytes));
    std::memcpy(f.bounce, buf + (at - addr), n);
    const ssize_t w = pwrite(f.direct_fd, f.bounce, n, static_cast<off_t>(at));
    if (w < 0 && errno == EINTR) continue;
    if (w < 0 && errno != EINVAL) return false;
    if (w <= 0 || static_cast<haddr_t>(w) % kBlock != 0) {
      // Refused, or a short write off the block grid: the rest goes buffered.
      if (w > 0) {
        at += static_cast<haddr_t>(w);
        direct_bytes += w;
      }
      close_direct(f);
      break;
    }
    at += static_cast<haddr_t>(w);
    direct_bytes += w;
  }
  return at >= last || write_all(f.fd, buf + (at - addr), last - at, at);
}

H5FD_t* open_file(const char* name, unsigned flags, hid_t, haddr_t maxaddr) {
  if (!name || !*name || maxaddr == 0 || maxaddr == HADDR_UNDEF || maxaddr > kMaxAddr) {
    H5Epush2(H5E_DEFAULT, __FILE__, "open_file", __LINE__, H5E_ERR_CLS, H5E_ARGS, H5E_BADVALUE,
             "invalid file name or address space");
    return nullptr;
  }
  int o = (flags & H5F_ACC_RDWR) ? O_RDWR : O_RDONLY;
  if (flags & H5F_ACC_TRUNC) o |= O_TRUNC;
  if (flags & H5F_ACC_CREAT) o |= O_CREAT;
  if (flags & H5F_ACC_EXCL) o |= O_EXCL;
  const int fd = open(name, o | O_CLOEXEC, 0666);
  if (fd < 0) {
    fail("open_file", H5E_CANTOPENFILE, name, errno);
    return nullptr;
  }
  struct stat st {};
  if (fstat(fd, &st) != 0) {
    const int err = errno;
    close(fd);
    fail("open_file", H5E_BADFILE, name, err);
    return nullptr;
  }
  auto* f = new DirectFile{};
  f->fd = fd;
  f->eof = static_cast<haddr_t>(st.st_size);
  f->device = st.st_dev;
  f->inode = st.st_ino;
  if (flags & H5F_ACC_RDWR) f->direct_fd = open(name, O_RDWR | O_DIRECT | O_CLOEXEC);
  return &f->pub;
}

herr_t close_file(H5FD_t* file) {
  DirectFile* f = as_file(file);
  close_direct(*f);
  const int err = close(f->fd) == 0 ? 0 : errno;
  std::free(f->bounce);
  delete f;
  return err == 0 ? 0 : fail("close_file", H5E_CANTCLOSEFILE, "closing the file", err);
}

int compare(const H5FD_t* a, const H5FD_t* b) {
  const DirectFile *f = as_file(a), *g = as_file(b);
  if (f->device != g->device) return f->device < g->device ? -1 : 1;
  if (f->inode != g->inode) return f->inode < g->inode ? -1 : 1;
  return 0;
}

// The POSIX driver's features, so that HDF5 lays the file out exactly as it would there.
herr_t query(const H5FD_t*, unsigned long* flags) {
  if (flags)
    *flags = H5FD_FEAT_AGGREGATE_METADATA | H5FD_FEAT_ACCUMULATE_METADATA | H5FD_FEAT_DATA_SIEVE |
             H5FD_FEAT_AGGREGATE_SMALLDATA | H5FD_FEAT_POSIX_COMPAT_HANDLE |
             H5FD_FEAT_SUPPORTS_SWMR_IO;
  return 0;
}

haddr_t get_eoa(const H5FD_t* file, H5FD_mem_t) { return as_file(file)->eoa; }

herr_t set_eoa(H5FD_t* file, H5FD_mem_t, haddr_t addr) {
  if (addr == HADDR_UNDEF || addr > kMaxAddr)
    return fail("set_eoa", H5E_OVERFLOW, "address beyond the largest file", EFBIG);
  as_file(file)->eoa = addr;
  return 0;
}

haddr_t get_eof(const H5FD_t* file, H5FD_mem_t) { return as_file(file)->eof; }

herr_t get_handle(H5FD_t* file, hid_t, void** handle) {
  if (!handle) return fail("get_handle", H5E_BADVALUE, "no handle pointer", EINVAL);
  *handle = &as_file(file)->fd;
  return 0;
}

herr_t read_file(H5FD_t* file, H5FD_mem_t, hid_t, haddr_t addr, size_t size, void* buffer) {
  DirectFile* f = as_file(file);
  if (addr == HADDR_UNDEF || addr + size > f->eoa)
    return fail("read_file", H5E_OVERFLOW, "read past the allocated end", EINVAL);
  auto* p = static_cast<unsigned char*>(buffer);
  while (size > 0) {
    const ssize_t n = pread(f->fd, p, size, static_cast<off_t>(addr));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail("read_file", H5E_READERROR, "reading the file", errno);
    if (n == 0) {  // past the end of the file: HDF5 reads zeros there
      std::memset(p, 0, size);
      break;
    }
    p += n;
    addr += static_cast<haddr_t>(n);
    size -= static_cast<std::size_t>(n);
  }
  return 0;
}

herr_t write_file(H5FD_t* file, H5FD_mem_t, hid_t, haddr_t addr, size_t size, const void* buffer) {
  DirectFile* f = as_file(file);
  if (addr == HADDR_UNDEF || addr + size > f->eoa)
    return fail("write_file", H5E_OVERFLOW, "write past the allocated end", EINVAL);
  const auto* p = static_cast<const unsigned char*>(buffer);
  const haddr_t end = addr + size;
  const haddr_t first = (addr + kBlock - 1) / kBlock * kBlock, last = end / kBlock * kBlock;
  bool ok;
  if (f->direct_fd >= 0 && size >= kDirectWriteMin && last > first)
    ok = write_all(f->fd, p, first - addr, addr) && write_direct(*f, p, addr, first, last) &&
         write_all(f->fd, p + (last - addr), end - last, last);
  else
    ok = write_all(f->fd, p, size, addr);
  if (!ok) return fail("write_file", H5E_WRITEERROR, "writing the file", errno);
  f->eof = std::max(f->eof, end);
  return 0;
}

herr_t truncate_file(H5FD_t* file, hid_t, hbool_t) {
  DirectFile* f = as_file(file);
  if (f->eoa == f->eof) return 0;
  if (ftruncate(f->fd, static_cast<off_t>(f->eoa)) != 0)
    return fail("truncate_file", H5E_SEEKERROR, "setting the file's length", errno);
  f->eof = f->eoa;
  return 0;
}

H5FD_class_t make_class() {
  H5FD_class_t c;
  std::memset(&c, 0, sizeof c);
  c.name = "grainflow_direct_write";
  c.maxaddr = kMaxAddr;
  c.fc_degree = H5F_CLOSE_WEAK;
  c.open = open_file;
  c.close = close_file;
  c.cmp = compare;
  c.query = query;
  c.get_eoa = get_eoa;
  c.set_eoa = set_eoa;
  c.get_eof = get_eof;
  c.get_handle = get_handle;
  c.read = read_file;
  c.write = write_file;
  c.truncate = truncate_file;
  // The POSIX driver's map: superblock, B-trees, heaps and object headers share one free
  // list, raw data and global heaps the other.
  const H5FD_mem_t map[H5FD_MEM_NTYPES] = H5FD_FLMAP_DICHOTOMY;
  std::copy(map, map + H5FD_MEM_NTYPES, c.fl_map);
  return c;
}

}  // namespace

std::string buffered_writes_error() {
  const char* value = std::getenv("GRAINFLOW_BUFFERED_WRITES");
  if (!value || !*value || std::string_view(value) == "0" || std::string_view(value) == "1")
    return {};
  return std::string("the environment variable GRAINFLOW_BUFFERED_WRITES is '") + value +
         "'; allowed values: 0 (large writes around the page cache, the default) or 1 (every "
         "write through the page cache)";
}

bool set_direct_write_driver(hid_t fapl) {
  if (const std::string error = buffered_writes_error(); !error.empty()) {
    H5Epush2(H5E_DEFAULT, __FILE__, "set_direct_write_driver", __LINE__, H5E_ERR_CLS, H5E_VFL,
             H5E_BADVALUE, "%s", error.c_str());
    return false;
  }
  if (const char* buffered = std::getenv("GRAINFLOW_BUFFERED_WRITES");
      buffered && std::string_view(buffered) == "1")
    return true;
  static const H5FD_class_t cls = make_class();
  static hid_t id = -1;
  // Registered again when HDF5 was closed and reopened in between (H5close drops drivers).
  if (id < 0 || H5Iis_valid(id) <= 0) id = H5FDregister(&cls);
  return id >= 0 && H5Pset_driver(fapl, id, nullptr) >= 0;
}

long long direct_write_bytes() { return direct_bytes.load(); }

}  // namespace grainflow
