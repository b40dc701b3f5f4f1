// Process-wide allocator settings for the solvers' allocation pattern.
//
// Newton steps allocate and free the same large temporaries again and again (assembly triplets,
// a sparse product, dense Schur blocks, CHOLMOD workspaces). glibc serves blocks above 128 KB by
// mmap and returns freed memory above the trim threshold to the kernel, so each step paid page
// faults to get the same memory back: the nonlinear L4-L5 disc study (3 mm cells, five load
// cases) took 1.49 million page faults and 12 s of system time beside 18 s of user time, and
// 8,245 faults, 0.7 s and 7.8 s with freed memory kept (peak RSS 44 → 47 MB;
// docs/benchmarks.md, "Keeping freed memory").
#pragma once

#include <malloc.h>

#include <cstdlib>

namespace spinesim {

/// Keeps freed memory in the process: blocks up to 32 MB (glibc's largest mmap threshold) come
/// from the heap, and the heap is not trimmed below 1 GB of free space. Call once, first thing
/// in main(). A threshold the environment sets (MALLOC_MMAP_THRESHOLD_, MALLOC_TRIM_THRESHOLD_,
/// GLIBC_TUNABLES) is left as it is.
inline void keep_freed_memory() {
  if (std::getenv("GLIBC_TUNABLES")) return;
  if (!std::getenv("MALLOC_MMAP_THRESHOLD_")) mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
  if (!std::getenv("MALLOC_TRIM_THRESHOLD_")) mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

}  // namespace spinesim
