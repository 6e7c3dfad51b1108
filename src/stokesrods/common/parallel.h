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

/// From this many nodes (all rods together) on, the loops over the rods at every step (frames,
/// elastic forces, the banded factors and solves, the preconditioner's rotations) run on the
/// threads. Below it a region's fork and join cost more than the rods' work it splits: on two
/// threads paper Fig. 1 (130 nodes) took 0.27 ms a step at h = 1 ms with these loops split,
/// 0.19–0.21 without; at 260 to 650 nodes splitting them was even or a few percent faster
/// (AMD EPYC host, docs/performance.md, session 34), and beyond the rods' work grows and the
/// fork's cost does not.
inline constexpr int kRodsInParallelFrom = 256;

/// From this many rows on, the dense mobility's passes (its products, the reuse's extrapolation
/// and rounding) run on the threads. Split, they made Fig. 1's step (390 rows) slower on two
/// threads than on one; four helices' (780) were even either way; LSBT's 1170 rows (2 × 195
/// nodes) stay split, where serial looked slower but within the host's noise (session 34).
inline constexpr int kDenseInParallelFromRows = 1024;

/// Whether a loop over `rods` rods of `nodes` nodes in all is worth splitting over the threads.
inline bool RodsInParallel(int rods, int nodes) { return rods > 1 && nodes >= kRodsInParallelFrom; }

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
