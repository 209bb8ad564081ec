/* mpi_count: an MPI profiling (PMPI) layer that counts what a program sends.
 *
 * LD_PRELOAD it into any MPI program. For every rank it counts, per kind of call, the
 * number of calls, the bytes the rank sends, and the wall time spent inside the calls.
 * MPI_Barrier splits a run into epochs: epoch 0 runs up to the first barrier, epoch 1 from
 * the first to the second, and so on. A program that brackets its timed loop by two barriers
 * (bench_strong_scaling does) gets exactly the loop's traffic as epoch 1. grainFoam calls no
 * barrier, so its whole run is epoch 0; two runs of different lengths, subtracted, give the
 * traffic per step.
 *
 * At MPI_Finalize each rank appends one line per epoch to $MPI_COUNT_OUT (default
 * mpi_count.txt):
 *   rank=R epoch=E kind=K calls=C bytes=B seconds=S
 * Kinds: p2p (Send, Isend, Sendrecv: bytes sent), allreduce, bcast, gather (Gather, Gatherv,
 * Allgather, Exscan: bytes contributed), wait (Wait*, Recv: time only).
 *
 * With $MPI_COUNT_STACKS set, each rank R also writes, per distinct call stack of a p2p,
 * allreduce, bcast or gather call, one line to the file $MPI_COUNT_STACKS.R:
 *   rank=R kind=K calls=C stack=MODULE+0xOFFSET;MODULE+0xOFFSET;...   (innermost first)
 * so that a script can tell who made the call (model.py --fluid: DEM, coupling or fluid) by
 * looking the offsets up in the modules' symbol tables.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <execinfo.h>
#include <mpi.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { P2P, ALLREDUCE, BCAST, GATHER, WAIT, KINDS };
static const char* kind_name[KINDS] = {"p2p", "allreduce", "bcast", "gather", "wait"};
enum { MAX_EPOCHS = 64 };
static long long calls[MAX_EPOCHS][KINDS], bytes[MAX_EPOCHS][KINDS];
static double seconds[MAX_EPOCHS][KINDS];
static int epoch = 0;

static long long size_of(MPI_Datatype t, int count) {
  int s = 0;
  PMPI_Type_size(t, &s);
  return (long long)s * count;
}
/* The call stacks, when $MPI_COUNT_STACKS is set: an open-addressing table keyed by the
 * return addresses. */
enum { MAX_FRAMES = 40, TABLE = 1 << 14 };
typedef struct {
  void* frames[MAX_FRAMES];
  int depth, kind;
  long long calls;
} Stack;
static Stack* stacks = NULL;
static int stacks_on = -1; /* -1: not looked at yet */

static void record_stack(int k) {
  if (stacks_on < 0) stacks_on = getenv("MPI_COUNT_STACKS") != NULL;
  if (!stacks_on || k == WAIT) return;
  if (!stacks) stacks = calloc(TABLE, sizeof(Stack));
  if (!stacks) return;
  void* f[MAX_FRAMES];
  const int n = backtrace(f, MAX_FRAMES);
  uint64_t h = (uint64_t)k * 0x9e3779b97f4a7c15ull;
  for (int i = 0; i < n; ++i) h = (h ^ (uint64_t)(uintptr_t)f[i]) * 0x100000001b3ull;
  for (uint64_t j = 0; j < TABLE; ++j) {
    Stack* s = &stacks[(h + j) & (TABLE - 1)];
    if (s->calls == 0) {
      memcpy(s->frames, f, sizeof(void*) * n);
      s->depth = n;
      s->kind = k;
    } else if (s->kind != k || s->depth != n || memcmp(s->frames, f, sizeof(void*) * n) != 0) {
      continue;
    }
    s->calls += 1;
    return;
  }
}

static void write_stacks(int rank) {
  const char* path = getenv("MPI_COUNT_STACKS");
  if (!stacks || !path) return;
  char name[4096];
  snprintf(name, sizeof name, "%s.%d", path, rank); /* a file per rank: no interleaved lines */
  FILE* f = fopen(name, "w");
  if (!f) return;
  for (int j = 0; j < TABLE; ++j) {
    const Stack* s = &stacks[j];
    if (s->calls == 0) continue;
    fprintf(f, "rank=%d kind=%s calls=%lld stack=", rank, kind_name[s->kind], s->calls);
    for (int i = 1; i < s->depth; ++i) { /* frame 0 is record_stack's caller, add() */
      Dl_info d;
      if (dladdr(s->frames[i], &d) && d.dli_fname)
        fprintf(f, "%s%s+0x%lx", i > 1 ? ";" : "", d.dli_fname,
                (unsigned long)((uintptr_t)s->frames[i] - (uintptr_t)d.dli_fbase));
      else
        fprintf(f, "%s?+0x%lx", i > 1 ? ";" : "", (unsigned long)(uintptr_t)s->frames[i]);
    }
    fputc('\n', f);
  }
  fclose(f);
}

static void add(int k, long long b, double t0) {
  calls[epoch][k] += 1;
  bytes[epoch][k] += b;
  seconds[epoch][k] += PMPI_Wtime() - t0;
  record_stack(k);
}

int MPI_Barrier(MPI_Comm c) {
  const int r = PMPI_Barrier(c);
  if (epoch + 1 < MAX_EPOCHS) ++epoch;
  return r;
}
int MPI_Send(const void* b, int n, MPI_Datatype t, int d, int g, MPI_Comm c) {
  const double t0 = PMPI_Wtime();
  const int r = PMPI_Send(b, n, t, d, g, c);
  add(P2P, size_of(t, n), t0);
  return r;
}
int MPI_Isend(const void* b, int n, MPI_Datatype t, int d, int g, MPI_Comm c, MPI_Request* q) {
  const double t0 = PMPI_Wtime();
  const int r = PMPI_Isend(b, n, t, d, g, c, q);
  add(P2P, size_of(t, n), t0);
  return r;
}
int MPI_Sendrecv(const void* sb, int sn, MPI_Datatype st, int d, int sg, void* rb, int rn,
                 MPI_Datatype rt, int s, int rg, MPI_Comm c, MPI_Status* status) {
  const double t0 = PMPI_Wtime();
  const int r = PMPI_Sendrecv(sb, sn, st, d, sg, rb, rn, rt, s, rg, c, status);
  add(P2P, size_of(st, sn), t0);
  return r;
}
int MPI_Recv(void* b, int n, MPI_Datatype t, int s, int g, MPI_Comm c, MPI_Status* st) {
  const double t0 = PMPI_Wtime();
  const int r = PMPI_Recv(b, n, t, s, g, c, st);
  add(WAIT, 0, t0);
  return r;
}
int MPI_Wait(MPI_Request* q, MPI_Status* st) {
  const double t0 = PMPI_Wtime();
  const int r = PMPI_Wait(q, st);
  add(WAIT, 0, t0);
  return r;
}
int MPI_Waitall(int n, MPI_Request* q, MPI_Status* st) {
  const double t0 = PMPI_Wtime();
  const int r = PMPI_Waitall(n, q, st);
  add(WAIT, 0, t0);
  return r;
}
int MPI_Allreduce(const void* sb, void* rb, int n, MPI_Datatype t, MPI_Op o, MPI_Comm c) {
  const double t0 = PMPI_Wtime();
  const int r = PMPI_Allreduce(sb, rb, n, t, o, c);
  add(ALLREDUCE, size_of(t, n), t0);
  return r;
}
int MPI_Bcast(void* b, int n, MPI_Datatype t, int root, MPI_Comm c) {
  const double t0 = PMPI_Wtime();
  const int r = PMPI_Bcast(b, n, t, root, c);
  add(BCAST, size_of(t, n), t0);
  return r;
}
int MPI_Gather(const void* sb, int sn, MPI_Datatype st, void* rb, int rn, MPI_Datatype rt,
               int root, MPI_Comm c) {
  const double t0 = PMPI_Wtime();
  const int r = PMPI_Gather(sb, sn, st, rb, rn, rt, root, c);
  add(GATHER, size_of(st, sn), t0);
  return r;
}
int MPI_Gatherv(const void* sb, int sn, MPI_Datatype st, void* rb, const int* rn,
                const int* disp, MPI_Datatype rt, int root, MPI_Comm c) {
  const double t0 = PMPI_Wtime();
  const int r = PMPI_Gatherv(sb, sn, st, rb, rn, disp, rt, root, c);
  add(GATHER, size_of(st, sn), t0);
  return r;
}
int MPI_Allgather(const void* sb, int sn, MPI_Datatype st, void* rb, int rn, MPI_Datatype rt,
                  MPI_Comm c) {
  const double t0 = PMPI_Wtime();
  const int r = PMPI_Allgather(sb, sn, st, rb, rn, rt, c);
  add(GATHER, size_of(st, sn), t0);
  return r;
}
int MPI_Exscan(const void* sb, void* rb, int n, MPI_Datatype t, MPI_Op o, MPI_Comm c) {
  const double t0 = PMPI_Wtime();
  const int r = PMPI_Exscan(sb, rb, n, t, o, c);
  add(GATHER, size_of(t, n), t0);
  return r;
}

int MPI_Finalize(void) {
  int rank = 0;
  PMPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const char* path = getenv("MPI_COUNT_OUT");
  FILE* f = fopen(path ? path : "mpi_count.txt", "a");
  if (f) {
    for (int e = 0; e <= epoch; ++e)
      for (int k = 0; k < KINDS; ++k)
        if (calls[e][k] > 0)
          fprintf(f, "rank=%d epoch=%d kind=%s calls=%lld bytes=%lld seconds=%.6f\n", rank, e,
                  kind_name[k], calls[e][k], bytes[e][k], seconds[e][k]);
    fclose(f);
  }
  write_stacks(rank);
  return PMPI_Finalize();
}
