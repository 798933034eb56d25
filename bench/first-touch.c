/* What this machine charges for fresh memory (bench/speed-notes.md, "Fresh
 * memory"): MB megabytes allocated, written once (the first touch: page
 * faults, and whatever the host does to back the pages) and again (memory
 * bandwidth alone), three times in one process; with HUGE 1 the block is
 * aligned to 2 MB and advised as huge-page memory, as host/big_array.hpp
 * advises gravcal's large arrays.
 *
 *   cc -O2 -o first-touch bench/first-touch.c && ./first-touch 300 0 && ./first-touch 300 1
 */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

int main(int argc, char** argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: first-touch MB HUGE(0|1)\n");
    return 2;
  }
  const size_t mb = (size_t)strtoul(argv[1], NULL, 10);
  const int huge = atoi(argv[2]);
  const size_t n = mb << 20;
  for (int r = 0; r < 3; ++r) {
    void* p = NULL;
    if (posix_memalign(&p, (size_t)2 << 20, n) != 0) return 1;
#ifdef MADV_HUGEPAGE
    if (huge) madvise(p, n, MADV_HUGEPAGE);
#endif
    const double t0 = now();
    memset(p, 1, n);
    const double t1 = now();
    memset(p, 2, n);
    const double t2 = now();
    printf("%s pages, %zu MB: first write %.3f s (%.2f GB/s), second %.3f s (%.2f GB/s)\n",
           huge ? "huge" : "4 KB", mb, t1 - t0, (double)mb / 1024 / (t1 - t0), t2 - t1,
           (double)mb / 1024 / (t2 - t1));
    free(p);
  }
  return 0;
}
