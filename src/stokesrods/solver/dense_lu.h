// The LU factorization (partial pivoting) of a dense square matrix and its solves, by LAPACK
// (getrf/getrs from OpenBLAS: blocked, vectorized for the CPU at hand; from n = kBlockedLuFrom
// getrf's blocked algorithm with its updates over the OpenMP threads). Eigen's PartialPivLU does
// the same arithmetic, but the build targets baseline x86-64, where its kernels use SSE2 only;
// for the capacitance's preconditioner (3M up to 3000) this is 2–4× faster (bench_step).
// Single precision for preconditioners (half the memory each solve streams), double otherwise.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "stokesrods/solver/lu_solve_avx512.h"

namespace stokesrods {

/// How DenseLu<float> keeps its factors for the solves.
enum class LuStorage {
  kNative,  ///< as getrf leaves them
  /// In IEEE half precision (U scaled by a power of two; lu_solve_avx512.h) where the CPU has
  /// AVX-512 BW and F16C or AVX2, FMA and F16C, else as kNative: half the bytes each solve
  /// streams, for preconditioners of many blocks whose factors do not stay in cache (a relative
  /// rounding of 2⁻¹¹ per entry).
  kHalf,
};

/// The factorization DenseLu::Compute takes, in place: getrf's factors and 1-based pivots (info as
/// getrf's: the first exactly zero pivot, or 0). Below kBlockedLuFrom one getrf; from there
/// LAPACK's blocked algorithm with each step's update over fixed column blocks spread over the
/// OpenMP threads (the same bits on any number of threads; dense_lu.cc).
inline constexpr int kBlockedLuFrom = 1024;
void LuFactor(int n, float* a, int* ipiv, int* info);
void LuFactor(int n, double* a, int* ipiv, int* info);

template <typename Scalar>
class DenseLu {
 public:
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

  /// Factorizes a (square). False if it is exactly singular (a zero pivot). `storage` kHalf is
  /// for single precision only.
  bool Compute(Matrix a, LuStorage storage = LuStorage::kNative);
  /// Whether the factors are kept in half precision (kHalf where the CPU allows it).
  bool half() const { return !half_.empty(); }
  /// x = A⁻¹ b in place (b's size must be the matrix's). In single precision on AVX-512 by a
  /// blocked substitution of our own (lu_solve_avx512.cc: 8.7 against getrs's 12.1 µs at
  /// n = 390, bench_step BM_FloatLuSolve, an Intel Xeon), on AVX2 with F16C by its twin below
  /// n = kParallelLuSolve (lu_solve_avx2.cc: 19.7 against 23.8 µs, an AMD EPYC), else by getrs;
  /// `use_lapack` forces getrs (tests). Factors in half precision are always solved by their own
  /// kernel (lu_solve_avx512.h).
  void Solve(Vector* b, bool use_lapack = false) const;
  /// Solve, bringing `next`'s factors into the L2 cache a little at a time along the way (a
  /// sequence of solves whose factors stream from memory: half precision below
  /// kParallelLuSolve; else `next`.Prefetch() first). The same x as Solve.
  void SolveThenPrefetch(Vector* b, const DenseLu& next) const;
  Eigen::Index size() const { return n_; }
  /// Asks the CPU to bring the factors into its L2 cache ahead of a Solve (no effect on results).
  void Prefetch() const;

 private:
  /// The half-precision kernel of the CPU (kHalf factors), `then` prefetched along the way.
  void SolveHalf(Vector* b, PrefetchSpan then) const;
  /// Where the factors the solves read are (half_ or lu_).
  PrefetchSpan FactorBytes() const;
  Matrix lu_;  ///< empty when the factors are in half_
  std::vector<int> pivots_;
  Eigen::Index n_ = 0;
  std::vector<std::uint16_t> half_;
  float half_scale_ = 1.0f;  ///< U's factor in half_
};

extern template class DenseLu<float>;
extern template class DenseLu<double>;

}  // namespace stokesrods
