// Loops over independent pieces on the OpenMP threads, or directly where a parallel region would
// not pay.
//
// OpenMP's `if` clause does not spare a region its cost: with the clause false, or with one
// thread, libgomp (GCC 12) still opens a team of one and closes it at a barrier that wakes its
// futex by a system call (config/linux/bar.c), ≈ 1.2 µs a region on this host against 0.01 µs
// for a short loop (docs/performance.md, session 34), and a step of paper Fig. 1 (0.24 ms on one
// thread) opened about twenty. So the loops that run at every step or product ask Parallel first
// and run in order on the calling thread where it says no. Each piece is independent of the
// others: the results are the same bits either way.
#pragma once

#ifdef _OPENMP
#include <omp.h>
#endif

namespace stokesrods {

/// Whether to open a parallel region: `worth` (the caller's judgement that the work is worth
/// splitting), more than one thread, and not already inside a region (a nested one would get one
/// thread).
inline bool Parallel(bool worth) {
#ifdef _OPENMP
  return worth && omp_get_max_threads() > 1 && !omp_in_parallel();
#else
  (void)worth;
  return false;
#endif
}

/// body(i) for i = 0 … count − 1: in equal runs over the threads (OpenMP's static schedule) where
/// Parallel(worth), else in order on this thread.
template <class Body>
void ForEachStatic(int count, bool worth, const Body& body) {
  if (!Parallel(worth)) {
    for (int i = 0; i < count; ++i) body(i);
    return;
  }
#pragma omp parallel for schedule(static)
  for (int i = 0; i < count; ++i) body(i);
}

/// The same, pieces handed to the threads one at a time as they free up (OpenMP's dynamic
/// schedule): for pieces of unequal cost.
template <class Body>
void ForEachDynamic(int count, bool worth, const Body& body) {
  if (!Parallel(worth)) {
    for (int i = 0; i < count; ++i) body(i);
    return;
  }
#pragma omp parallel for schedule(dynamic)
  for (int i = 0; i < count; ++i) body(i);
}

}  // namespace stokesrods
