// The machine's limits that bound grain's time loop (docs/performance.md, "How far the loop is
// from the machine's limits"):
//   - memory bandwidth: the STREAM triad a[i] = b[i] + s c[i] (McCalpin 1995) over arrays far
//     beyond the caches, on 1 and on 2 threads (each thread its own slice, first touched by
//     itself); bytes counted as STREAM counts them (24 per element: two reads, one write) and
//     with the write-allocate read a cache line fill makes of the destination (32);
//   - the core clock: a chain of dependent integer adds (one per cycle on any x86 core);
//   - the issue rate: independent integer adds (what the core retires per cycle at best);
//   - the SSE2 square root and division (sqrtpd, divpd on two doubles): cycles per instruction
//     when independent (throughput) and when each waits for the last (latency), with the
//     operands the pair kernel sees (not 0 or 1, which some dividers finish early).
// Every figure is the best of --repeat runs: the triad timed with the steady clock and with the
// threads' CPU time (other jobs' memory traffic lowers both), the rest with the thread's CPU time
// (time without a core does not count); the cycle figures are those seconds times the frequency
// found by the add chain. --mib 1 (3 MiB in all) keeps the triad in the last-level cache.
//
//   bench_machine [--mib 96] [--repeat 30]
//
// --mib: the size of each of the triad's three arrays, summed over threads.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <thread>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The calling thread's CPU time [s] (not the time it waits for a core: the machine is shared).
double thread_seconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Best wall time of `repeat` runs of f().
template <class F>
double best_of(int repeat, F f) {
  double best = 1e300;
  for (int r = 0; r < repeat; ++r) {
    const auto t0 = Clock::now();
    f();
    best = std::min(best, seconds_since(t0));
  }
  return best;
}

// Best thread CPU time of `repeat` runs of f() (one thread: the caller).
template <class F>
double best_cpu_of(int repeat, F f) {
  double best = 1e300;
  for (int r = 0; r < repeat; ++r) {
    const double t0 = thread_seconds();
    f();
    best = std::min(best, thread_seconds() - t0);
  }
  return best;
}

struct TriadTimes {
  double wall;  // the pass's wall time
  double cpu;   // the largest of the threads' CPU times in the pass
};

// The triad on `threads` threads, each over its own slice of n / threads elements: the best
// times of `repeat` passes (all threads start each pass together and the pass ends with the
// last). On a shared machine the CPU time leaves out the time a thread waits for a core (not
// the other jobs' memory traffic).
TriadTimes triad_seconds(long n, int threads, int repeat) {
  const long slice = n / threads;
  std::vector<double*> a(threads), b(threads), c(threads);
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&, t] {
      a[t] = new double[slice];
      b[t] = new double[slice];
      c[t] = new double[slice];
      for (long i = 0; i < slice; ++i) a[t][i] = 0, b[t][i] = 1, c[t][i] = 2;  // first touch
    });
  for (auto& th : pool) th.join();
  const double s = 3;
  std::vector<double> cpu(threads);
  double best_cpu = 1e300;
  const double best = best_of(repeat, [&] {
    std::vector<std::thread> workers;
    for (int t = 0; t < threads; ++t)
      workers.emplace_back([&, t] {
        const double t0 = thread_seconds();
        double* __restrict__ x = a[t];
        const double* __restrict__ y = b[t];
        const double* __restrict__ z = c[t];
        for (long i = 0; i < slice; ++i) x[i] = y[i] + s * z[i];
        cpu[t] = thread_seconds() - t0;
      });
    for (auto& th : workers) th.join();
    best_cpu = std::min(best_cpu, *std::max_element(cpu.begin(), cpu.end()));
  });
  double check = 0;
  for (int t = 0; t < threads; ++t) {
    check += a[t][slice - 1];
    delete[] a[t];
    delete[] b[t];
    delete[] c[t];
  }
  if (check != 7.0 * threads) std::fprintf(stderr, "triad: wrong result %g\n", check);
  return {best, best_cpu};
}

constexpr long kLoops = 5'000'000;

// kLoops x 8 dependent adds.
double add_chain_seconds(int repeat) {
  return best_cpu_of(repeat, [] {
    long x = 0;
    for (long k = 0; k < kLoops; ++k)
      asm volatile(
          "add $1, %0\n\tadd $1, %0\n\tadd $1, %0\n\tadd $1, %0\n\t"
          "add $1, %0\n\tadd $1, %0\n\tadd $1, %0\n\tadd $1, %0"
          : "+r"(x));
    if (x != 8 * kLoops) std::fprintf(stderr, "add chain: wrong count\n");
  });
}

// kLoops x 12 independent adds (four chains) and the loop's own two instructions.
double add_independent_seconds(int repeat) {
  return best_cpu_of(repeat, [] {
    long x0 = 0, x1 = 0, x2 = 0, x3 = 0;
    for (long k = 0; k < kLoops; ++k)
      asm volatile(
          "add $1, %0\n\tadd $1, %1\n\tadd $1, %2\n\tadd $1, %3\n\t"
          "add $1, %0\n\tadd $1, %1\n\tadd $1, %2\n\tadd $1, %3\n\t"
          "add $1, %0\n\tadd $1, %1\n\tadd $1, %2\n\tadd $1, %3"
          : "+r"(x0), "+r"(x1), "+r"(x2), "+r"(x3));
    if (x0 + x1 + x2 + x3 != 12 * kLoops) std::fprintf(stderr, "adds: wrong count\n");
  });
}

#if defined(__SSE2__)
constexpr long kOpLoops = 1'000'000;

// kOpLoops x 8 instructions `op` (sqrtpd or divpd) on two doubles: independent (each from the
// same sources into its own register) or a chain (each on the last one's result).
template <bool Chain>
double sse_op_seconds(const char* op, int repeat) {
  const std::string name = op;
  return best_cpu_of(repeat, [&] {
    double in[2] = {1.2345678901234567, 2.3456789012345678};
    double out[2];
    if (name == "sqrtpd" && !Chain) {
      asm volatile(
          "movupd (%1), %%xmm0\n\t"
          "mov %2, %%rcx\n"
          "1:\n\t"
          "sqrtpd %%xmm0, %%xmm1\n\tsqrtpd %%xmm0, %%xmm2\n\tsqrtpd %%xmm0, %%xmm3\n\t"
          "sqrtpd %%xmm0, %%xmm4\n\tsqrtpd %%xmm0, %%xmm5\n\tsqrtpd %%xmm0, %%xmm6\n\t"
          "sqrtpd %%xmm0, %%xmm7\n\tsqrtpd %%xmm0, %%xmm8\n\t"
          "dec %%rcx\n\tjnz 1b\n\t"
          "movupd %%xmm8, (%0)"
          :
          : "r"(out), "r"(in), "r"(kOpLoops)
          : "rcx", "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7", "xmm8",
            "memory");
    } else if (name == "divpd" && !Chain) {
      asm volatile(
          "movupd (%1), %%xmm0\n\t"
          "mov %2, %%rcx\n"
          "1:\n\t"
          "movapd %%xmm0, %%xmm1\n\tdivpd %%xmm0, %%xmm1\n\t"
          "movapd %%xmm0, %%xmm2\n\tdivpd %%xmm0, %%xmm2\n\t"
          "movapd %%xmm0, %%xmm3\n\tdivpd %%xmm0, %%xmm3\n\t"
          "movapd %%xmm0, %%xmm4\n\tdivpd %%xmm0, %%xmm4\n\t"
          "movapd %%xmm0, %%xmm5\n\tdivpd %%xmm0, %%xmm5\n\t"
          "movapd %%xmm0, %%xmm6\n\tdivpd %%xmm0, %%xmm6\n\t"
          "movapd %%xmm0, %%xmm7\n\tdivpd %%xmm0, %%xmm7\n\t"
          "movapd %%xmm0, %%xmm8\n\tdivpd %%xmm0, %%xmm8\n\t"
          "dec %%rcx\n\tjnz 1b\n\t"
          "movupd %%xmm8, (%0)"
          :
          : "r"(out), "r"(in), "r"(kOpLoops)
          : "rcx", "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7", "xmm8",
            "memory");
    } else if (name == "sqrtpd") {  // chain: x <- sqrt(x) tends to 1; keep x = in by x*x
      // sqrt(x) then multiply by itself gives x back to round-off (the mulpd's latency is
      // part of the chain and reported with it).
      asm volatile(
          "movupd (%1), %%xmm0\n\t"
          "mov %2, %%rcx\n"
          "1:\n\t"
          "sqrtpd %%xmm0, %%xmm0\n\tmulpd %%xmm0, %%xmm0\n\t"
          "sqrtpd %%xmm0, %%xmm0\n\tmulpd %%xmm0, %%xmm0\n\t"
          "sqrtpd %%xmm0, %%xmm0\n\tmulpd %%xmm0, %%xmm0\n\t"
          "sqrtpd %%xmm0, %%xmm0\n\tmulpd %%xmm0, %%xmm0\n\t"
          "sqrtpd %%xmm0, %%xmm0\n\tmulpd %%xmm0, %%xmm0\n\t"
          "sqrtpd %%xmm0, %%xmm0\n\tmulpd %%xmm0, %%xmm0\n\t"
          "sqrtpd %%xmm0, %%xmm0\n\tmulpd %%xmm0, %%xmm0\n\t"
          "sqrtpd %%xmm0, %%xmm0\n\tmulpd %%xmm0, %%xmm0\n\t"
          "dec %%rcx\n\tjnz 1b\n\t"
          "movupd %%xmm0, (%0)"
          :
          : "r"(out), "r"(in), "r"(kOpLoops)
          : "rcx", "xmm0", "memory");
    } else {  // divpd chain: x <- (x / y) * y keeps x
      asm volatile(
          "movupd (%1), %%xmm0\n\t"
          "movapd %%xmm0, %%xmm1\n\t"
          "mov %2, %%rcx\n"
          "1:\n\t"
          "divpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\t"
          "divpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\t"
          "divpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\t"
          "divpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\t"
          "divpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\t"
          "divpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\t"
          "divpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\t"
          "divpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\t"
          "dec %%rcx\n\tjnz 1b\n\t"
          "movupd %%xmm0, (%0)"
          :
          : "r"(out), "r"(in), "r"(kOpLoops)
          : "rcx", "xmm0", "xmm1", "memory");
    }
  });
}

// The latency of mulpd, to take out of the chains above: a chain of multiplications by 1.
double mulpd_chain_seconds(int repeat) {
  return best_cpu_of(repeat, [] {
    double in[2] = {1.0, 1.0}, out[2];
    asm volatile(
        "movupd (%1), %%xmm0\n\t"
        "movapd %%xmm0, %%xmm1\n\t"
        "mov %2, %%rcx\n"
        "1:\n\t"
        "mulpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\t"
        "mulpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\t"
        "mulpd %%xmm1, %%xmm0\n\tmulpd %%xmm1, %%xmm0\n\t"
        "dec %%rcx\n\tjnz 1b\n\t"
        "movupd %%xmm0, (%0)"
        :
        : "r"(out), "r"(in), "r"(kOpLoops)
        : "rcx", "xmm0", "xmm1", "memory");
  });
}
#endif

}  // namespace

int main(int argc, char** argv) {
  long mib = 96;
  int repeat = 30;
  for (int k = 1; k + 1 < argc; k += 2) {
    const std::string a = argv[k];
    if (a == "--mib") mib = std::atol(argv[k + 1]);
    else if (a == "--repeat") repeat = std::atoi(argv[k + 1]);
    else {
      std::fprintf(stderr, "usage: bench_machine [--mib 96] [--repeat 30]\n");
      return 2;
    }
  }
  const long n = mib * 1024 * 1024 / 8;
  std::printf("triad a = b + s c, three arrays of %ld MiB in all threads together, best of %d\n",
              mib, repeat);
  for (int threads : {1, 2}) {
    const TriadTimes t = triad_seconds(n, threads, repeat);
    std::printf(
        "  %d thread(s): wall time %.2f GB/s (24 B per element), %.2f GB/s (32 B, "
        "write-allocate); CPU time %.2f GB/s, %.2f GB/s\n",
        threads, 24.0 * n / t.wall / 1e9, 32.0 * n / t.wall / 1e9, 24.0 * n / t.cpu / 1e9,
        32.0 * n / t.cpu / 1e9);
  }
  const double chain = add_chain_seconds(repeat);
  const double ghz = 8.0 * kLoops / chain / 1e9;
  std::printf("clock (dependent adds, 1 per cycle): %.3f GHz\n", ghz);
  const double indep = add_independent_seconds(repeat);
  std::printf("independent adds: %.2f instructions per cycle (12 adds + 2 loop instructions)\n",
              14.0 * kLoops / (indep * ghz * 1e9));
#if defined(__SSE2__)
  const double cycles_per = 1e9 * ghz / (8.0 * kOpLoops);  // cycles per instruction per second
  const double mul = mulpd_chain_seconds(repeat) * cycles_per;
  std::printf("mulpd latency: %.1f cycles\n", mul);
  for (const char* op : {"sqrtpd", "divpd"}) {
    const double thr = sse_op_seconds<false>(op, repeat) * cycles_per;
    const double lat = sse_op_seconds<true>(op, repeat) * cycles_per - mul;
    std::printf("%s (two doubles): %.1f cycles apart when independent, %.1f latency\n", op, thr,
                lat);
  }
#endif
  return 0;
}
