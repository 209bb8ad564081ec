#include "dem/io/hdf5_checksum.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "dem/io/hdf5_errors.hpp"

namespace grainflow {

hsize_t checksum_chunk_rows(int rank, const hsize_t* dims, std::size_t element_bytes) {
  const hsize_t row_bytes = (rank == 2 ? dims[1] : 1) * std::max<std::size_t>(element_bytes, 1);
  // Equal chunks of at most 1 MiB: HDF5 allocates whole chunks, so a last chunk mostly
  // empty would waste its size in the file.
  const hsize_t max_rows = std::max<hsize_t>((hsize_t(1) << 20) / row_bytes, 1);
  const hsize_t chunks = (dims[0] + max_rows - 1) / max_rows;
  return (dims[0] + chunks - 1) / chunks;
}

bool add_checksum(hid_t dcpl, int rank, const hsize_t* dims, std::size_t element_bytes) {
  if (dims[0] == 0) return true;
  const hsize_t chunk[2] = {checksum_chunk_rows(rank, dims, element_bytes), rank == 2 ? dims[1] : 1};
  return H5Pset_chunk(dcpl, rank, chunk) >= 0 && H5Pset_fletcher32(dcpl) >= 0;
}

namespace {

// Fletcher's two running sums over 16-bit words w_0, w_1, ...: s1 = sum of the words, s2 = the
// sum of s1 after each word, i.e. each word times the number of words from it to the end. Both
// are kept modulo 65535 (exact: HDF5 reduces with (x & 0xffff) + (x >> 16), which keeps the
// residue, and its blocks of 360 words never overflow 32 bits).
struct FletcherSums {
  std::uint64_t s1 = 0;
  std::uint64_t s2 = 0;

  // One more word.
  void add(std::uint64_t w) {
    s1 += w;
    s2 += s1;
  }
  // A block of m words whose plain sum is `sum` and whose weighted sum, each word times the
  // number of words from it to the block's end, is `weighted`.
  void add_block(std::uint64_t m, std::uint64_t sum, std::uint64_t weighted) {
    s2 += m * s1 + weighted;
    s1 += sum;
    reduce();
  }
  void reduce() {
    s1 %= 65535;
    s2 %= 65535;
  }
};

std::uint64_t big_endian_word(const unsigned char* p) {
  return (std::uint64_t{p[0]} << 8) | p[1];
}

}  // namespace

std::uint32_t fletcher32(const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::size_t words = bytes / 2;
  FletcherSums sums;
  bool nonzero = false;
#if defined(__SSE2__)
  // Eight words per 16 bytes, one per 32-bit lane in two registers (lanes 0-3 the first four
  // words, 4-7 the last four). Over T iterations lane l sums A_l = sum_t w(8t + l) and
  // B_l = sum_t (T - t) w(8t + l); the block's weighted sum is then sum_l (8 B_l - l A_l).
  // T = 256 keeps B below 65535 * 256 * 257 / 2 < 2^32.
  constexpr std::size_t block_iterations = 256;
  const __m128i zero = _mm_setzero_si128();
  __m128i any = zero;
  while (words >= 8) {
    const std::size_t iterations = std::min(words / 8, block_iterations);
    __m128i a_lo = zero, a_hi = zero, b_lo = zero, b_hi = zero;
    for (std::size_t t = 0; t < iterations; ++t, p += 16) {
      const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
      any = _mm_or_si128(any, v);
      const __m128i w = _mm_or_si128(_mm_slli_epi16(v, 8), _mm_srli_epi16(v, 8));
      a_lo = _mm_add_epi32(a_lo, _mm_unpacklo_epi16(w, zero));
      a_hi = _mm_add_epi32(a_hi, _mm_unpackhi_epi16(w, zero));
      b_lo = _mm_add_epi32(b_lo, a_lo);
      b_hi = _mm_add_epi32(b_hi, a_hi);
    }
    alignas(16) std::uint32_t a[8], b[8];
    _mm_store_si128(reinterpret_cast<__m128i*>(a), a_lo);
    _mm_store_si128(reinterpret_cast<__m128i*>(a + 4), a_hi);
    _mm_store_si128(reinterpret_cast<__m128i*>(b), b_lo);
    _mm_store_si128(reinterpret_cast<__m128i*>(b + 4), b_hi);
    std::uint64_t sum = 0, weighted = 0;
    for (std::uint64_t l = 0; l < 8; ++l) {
      sum += a[l];
      weighted += 8 * std::uint64_t{b[l]} - l * a[l];
    }
    sums.add_block(8 * iterations, sum, weighted);
    words -= 8 * iterations;
  }
  nonzero = _mm_movemask_epi8(_mm_cmpeq_epi8(any, zero)) != 0xffff;
#endif
  // The words left (all of them without SSE2), reduced often enough to stay far from overflow.
  for (std::size_t k = 0; k < words; ++k, p += 2) {
    const std::uint64_t w = big_endian_word(p);
    nonzero = nonzero || w != 0;
    sums.add(w);
    if ((k & 0xffff) == 0xffff) sums.reduce();
  }
  if (bytes % 2) {  // an odd byte: the high byte of one more word
    nonzero = nonzero || *p != 0;
    sums.add(std::uint64_t{*p} << 8);
  }
  sums.reduce();
  // HDF5's reduction never brings a non-zero sum to 0: a multiple of 65535 stays 65535. Both
  // sums are non-zero exactly when some word is.
  const auto fold = [nonzero](std::uint64_t s) {
    return static_cast<std::uint32_t>(nonzero && s == 0 ? 65535 : s);
  };
  return (fold(sums.s2) << 16) | fold(sums.s1);
}

bool write_checksummed(hid_t dataset, int rank, const hsize_t* dims, std::size_t element_bytes,
                       const void* data) {
  if (dims[0] == 0) return true;
  const std::size_t row_bytes = (rank == 2 ? dims[1] : 1) * element_bytes;
  const hsize_t rows = checksum_chunk_rows(rank, dims, element_bytes);
  const std::size_t chunk_bytes = rows * row_bytes;
  // One chunk and its checksum; the last chunk's rows past the data are zeros (HDF5 stores and
  // checks a partial last chunk at its full size and reads only the rows inside).
  std::vector<unsigned char> chunk(chunk_bytes + 4);
  const auto* source = static_cast<const unsigned char*>(data);
  for (hsize_t first = 0; first < dims[0]; first += rows) {
    const std::size_t n = std::min(rows, dims[0] - first) * row_bytes;
    std::memcpy(chunk.data(), source + first * row_bytes, n);
    std::memset(chunk.data() + n, 0, chunk_bytes - n);
    const std::uint32_t sum = fletcher32(chunk.data(), chunk_bytes);
    for (std::size_t b = 0; b < 4; ++b)  // little-endian, as HDF5's filter stores it
      chunk[chunk_bytes + b] = static_cast<unsigned char>(sum >> (8 * b));
    const hsize_t offset[2] = {first, 0};
    if (H5Dwrite_chunk(dataset, H5P_DEFAULT, 0, offset, chunk_bytes + 4, chunk.data()) < 0)
      return false;
  }
  return true;
}

hid_t checksummed_layout(int rank, const hsize_t* dims, std::size_t element_bytes) {
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  if (dcpl >= 0 && !add_checksum(dcpl, rank, dims, element_bytes)) {
    H5Pclose(dcpl);
    return -1;
  }
  return dcpl;
}

std::string verify_stored(hid_t dataset, hid_t mem_type, const void* values,
                          bool require_checksum) {
  const hid_t dcpl = H5Dget_create_plist(dataset);
  if (dcpl < 0) return "its storage settings cannot be read";
  const bool chunked = H5Pget_layout(dcpl) == H5D_CHUNKED;
  int index = -1;  // the Fletcher32 filter's place in the pipeline
  const int filters = H5Pget_nfilters(dcpl);
  for (int i = 0; i < filters; ++i) {
    unsigned flags = 0;
    std::size_t n = 0;
    if (H5Pget_filter2(dcpl, static_cast<unsigned>(i), &flags, &n, nullptr, 0, nullptr, nullptr) ==
        H5Z_FILTER_FLETCHER32)
      index = i;
  }
  hsize_t chunk[2] = {0, 0};
  const int chunk_rank = chunked ? H5Pget_chunk(dcpl, 2, chunk) : 0;
  H5Pclose(dcpl);
  if (index < 0 || !chunked)
    return require_checksum ? "it has no Fletcher32 checksum, which every dataset of this file "
                              "was written with (the file's record of its filters is damaged)"
                            : "";
  if (filters != 1) return "";  // not a layout grainflow writes: HDF5's own checks stand
  const hid_t space = H5Dget_space(dataset);
  hsize_t dims[2] = {0, 1};
  const int rank = H5Sget_simple_extent_dims(space, dims, nullptr);
  hsize_t stored = 0;
  const bool counted = H5Dget_num_chunks(dataset, space, &stored) >= 0;
  H5Sclose(space);
  if (rank < 1 || rank > 2 || chunk_rank != rank || chunk[0] == 0 ||
      (rank == 2 && chunk[1] != dims[1]))
    return "";  // chunks not of whole rows: not grainflow's layout
  const hsize_t rows = dims[0], cols = rank == 2 ? dims[1] : 1;
  const hsize_t expected = (rows + chunk[0] - 1) / chunk[0];
  if (!counted || stored != expected)
    return "it has " + std::to_string(counted ? stored : 0) + " stored chunk(s) where its " +
           std::to_string(rows) + " rows need " + std::to_string(expected) +
           " (the file's record of its chunks is damaged)";
  const hid_t file_type = H5Dget_type(dataset);
  const std::size_t element = H5Tget_size(file_type);
  const bool same_type = H5Tequal(file_type, mem_type) > 0;
  H5Tclose(file_type);
  const std::size_t row_bytes = cols * element;
  std::vector<unsigned char> raw;
  for (hsize_t c = 0; c < expected; ++c) {
    const hsize_t offset[2] = {c * chunk[0], 0};
    const std::string which =
        "chunk " + std::to_string(c) + " (rows " + std::to_string(offset[0]) + " on)";
    hsize_t size = 0;
    if (H5Dget_chunk_storage_size(dataset, offset, &size) < 0 || size < 4)
      return which + " is not where the file's record says (the record is damaged)";
    raw.resize(size);
    std::uint32_t mask = 0;
    if (H5Dread_chunk(dataset, H5P_DEFAULT, offset, &mask, raw.data()) < 0)
      return which + " cannot be read raw (the file's record of it is damaged)";
    if (mask & (1u << index))
      return which +
             " is marked as stored without its Fletcher32 checksum, which every chunk "
             "was written with (the file's record of it is damaged)";
    const std::uint32_t tail = std::uint32_t(raw[size - 4]) | std::uint32_t(raw[size - 3]) << 8 |
                               std::uint32_t(raw[size - 2]) << 16 |
                               std::uint32_t(raw[size - 1]) << 24;
    if (fletcher32(raw.data(), size - 4) != tail)
      return which + ": its Fletcher32 checksum does not match the data";
    const hsize_t chunk_rows = std::min(chunk[0], rows - offset[0]);
    if (size - 4 < chunk_rows * row_bytes)
      return which + " holds " + std::to_string(size - 4) + " bytes, fewer than its " +
             std::to_string(chunk_rows) + " rows";
    if (same_type &&
        std::memcmp(raw.data(), static_cast<const unsigned char*>(values) + offset[0] * row_bytes,
                    chunk_rows * row_bytes) != 0)
      return which +
             ": the values HDF5 read are not the ones stored (the file's record of "
             "where the chunk lies is damaged; HDF5 read its fill value, zeros, instead)";
  }
  return "";
}

std::string read_failure_reason() {
  std::string reason = hdf5_reason();
  std::string lower = reason;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower.find("fletcher32") != std::string::npos)
    return "its Fletcher32 checksum does not match the data (" + reason +
           "): the file was changed or damaged after it was written";
  return reason;
}

}  // namespace grainflow
