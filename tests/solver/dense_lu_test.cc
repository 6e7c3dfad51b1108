// DenseLu (LAPACK getrf/getrs) against Eigen's PartialPivLU, in double and single precision,
// and the BLAS products of solver/blas.h against Eigen's.
#include "stokesrods/solver/dense_lu.h"

#include <gtest/gtest.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <Eigen/LU>
#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "stokesrods/solver/blas.h"
#include "stokesrods/solver/lu_solve_avx512.h"

extern "C" void sgetrf_(const int* m, const int* n, float* a, const int* lda, int* ipiv, int* info);
extern "C" void sgetrs_(const char* trans, const int* n, const int* nrhs, const float* a,
                        const int* lda, const int* ipiv, float* b, const int* ldb, int* info,
                        std::size_t trans_len);

namespace stokesrods {
namespace {

#if defined(__x86_64__)
__attribute__((target("f16c"))) float Widen(std::uint16_t h) { return _cvtsh_ss(h); }
#else
float Widen(std::uint16_t) { return 0.0f; }
#endif

template <typename Scalar>
Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic> RandomMatrix(int n, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic> a(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) a(i, j) = static_cast<Scalar>(normal(*rng));
  return a;
}

// random + 2n I with its rows shuffled: well conditioned, and every column pivots.
Eigen::MatrixXf ShuffledDominant(const Eigen::MatrixXf& random, std::mt19937* rng) {
  const Eigen::Index n = random.rows();
  Eigen::PermutationMatrix<Eigen::Dynamic> shuffle(n);
  shuffle.setIdentity();
  std::shuffle(shuffle.indices().data(), shuffle.indices().data() + n, *rng);
  return shuffle * (random + static_cast<float>(2 * n) * Eigen::MatrixXf::Identity(n, n));
}

// The single-precision blocked solves and their half-precision twins that this CPU runs
// (DenseLu takes the widest; the narrower are checked here directly).
struct LuKernels {
  const char* name;
  void (*solve)(int, const float*, const int*, float*);
  bool (*to_half)(int, const float*, std::uint16_t*, float*);
  void (*solve_half)(int, const std::uint16_t*, const int*, float, float*, PrefetchSpan);
  bool half;  // whether the CPU runs to_half and solve_half
};
std::vector<LuKernels> KernelsHere() {
  std::vector<LuKernels> kernels;
  if (HasLuSolveAvx512())
    kernels.push_back({"AVX-512", LuSolveAvx512, ConvertLuToHalf, LuSolveHalfAvx512,
                       HasLuSolveHalfAvx512()});
  if (HasLuSolveAvx2())
    kernels.push_back({"AVX2", LuSolveAvx2, ConvertLuToHalfF16c, LuSolveHalfAvx2, true});
  return kernels;
}

// The factors and pivots of a as DenseLu::Compute takes them (LuFactor: getrf's, blocked over
// the threads from kBlockedLuFrom).
void Factor(const Eigen::MatrixXf& a, Eigen::MatrixXf* factors, std::vector<int>* pivots) {
  const int n = static_cast<int>(a.rows());
  *factors = a;
  pivots->resize(static_cast<size_t>(n));
  int info = 0;
  LuFactor(n, factors->data(), pivots->data(), &info);
  ASSERT_EQ(info, 0);
}

// Residuals |A x − b| / (|A| |x|): measured ~1e-16 (double) and ~1e-7 (float), like Eigen's.
TEST(DenseLu, SolvesLikeEigensPartialPivLu) {
  std::mt19937 rng(5);
  for (const int n : {1, 2, 7, 64, 390}) {
    const Eigen::MatrixXd a = RandomMatrix<double>(n, &rng);
    const Eigen::VectorXd b = RandomMatrix<double>(n, &rng).col(0);
    DenseLu<double> lu;
    ASSERT_TRUE(lu.Compute(a));
    Eigen::VectorXd x = b;
    lu.Solve(&x);
    const Eigen::VectorXd reference = a.partialPivLu().solve(b);
    EXPECT_LT((a * x - b).norm() / (a.norm() * x.norm()), 1e-14) << n;
    EXPECT_LT((x - reference).norm() / reference.norm(), 1e-10) << n;

    const Eigen::MatrixXf af = a.cast<float>();
    DenseLu<float> luf;
    ASSERT_TRUE(luf.Compute(af));
    Eigen::VectorXf xf = b.cast<float>();
    luf.Solve(&xf);
    EXPECT_LT((af * xf - b.cast<float>()).norm() / (af.norm() * xf.norm()), 1e-5f) << n;
  }
}

// The single-precision solve of one vector by each blocked substitution the CPU runs (AVX-512,
// AVX2) against getrs, on sizes around their blocks of 32 columns and 32 or 64 rows, and from 1024
// on (the panels over the OpenMP threads, blocks of 128 columns): on random matrices the same
// residuals; on well-conditioned ones (diagonally dominant, rows shuffled so that every column
// pivots) the same solution to float rounding.
TEST(DenseLu, TheBlockedSingleSolveMatchesGetrs) {
  const std::vector<LuKernels> kernels = KernelsHere();
  if (kernels.empty()) GTEST_SKIP() << "neither AVX-512 nor AVX2 here: getrs is the only path";
  std::mt19937 rng(9);
  for (const int n : {1, 5, 31, 32, 33, 63, 64, 65, 100, 390, 1023, 1024, 1100, 1153, 2400}) {
    const Eigen::MatrixXf random = RandomMatrix<float>(n, &rng);
    const Eigen::MatrixXf dominant = ShuffledDominant(random, &rng);
    const Eigen::VectorXf b = RandomMatrix<float>(n, &rng).col(0);
    for (const Eigen::MatrixXf* a : {&random, &dominant}) {
      DenseLu<float> lu;
      ASSERT_TRUE(lu.Compute(*a));
      Eigen::VectorXf widest = b, lapack = b;
      lu.Solve(&widest);
      lu.Solve(&lapack, true);
      Eigen::MatrixXf factors;
      std::vector<int> pivots;
      Factor(*a, &factors, &pivots);
      const float lapack_residual = (*a * lapack - b).norm() / (a->norm() * lapack.norm());
      for (const LuKernels& kernel : kernels) {
        Eigen::VectorXf fast = b;
        kernel.solve(n, factors.data(), pivots.data(), fast.data());
        // DenseLu's solve is the widest kernel's (on AVX2 getrs from kParallelLuSolve on).
        const bool dense_lu_takes_it = kernel.solve == LuSolveAvx512 || n < kParallelLuSolve;
        if (&kernel == &kernels.front() && dense_lu_takes_it) {
          EXPECT_EQ(fast, widest) << kernel.name << " " << n;
        }
        const float residual = (*a * fast - b).norm() / (a->norm() * fast.norm());
        EXPECT_LT(residual, 1e-5f) << kernel.name << " " << n;
        EXPECT_LT(residual, 10.0f * lapack_residual + 1e-6f) << kernel.name << " " << n;
        if (a == &dominant) {
          EXPECT_LT((fast - lapack).norm(), 1e-5f * lapack.norm()) << kernel.name << " " << n;
        }
      }
    }
  }
}

// From n = 1024 the solves' panels run over the OpenMP threads: the same result on any number,
// for each kernel, single and half precision.
TEST(DenseLu, TheBlockedSingleSolveDoesNotDependOnTheThreadCount) {
#ifdef _OPENMP
  const std::vector<LuKernels> kernels = KernelsHere();
  if (kernels.empty()) GTEST_SKIP() << "neither AVX-512 nor AVX2 here: getrs is the only path";
  std::mt19937 rng(4);
  const int n = 1500;
  const Eigen::MatrixXf a = RandomMatrix<float>(n, &rng);
  const Eigen::VectorXf b = RandomMatrix<float>(n, &rng).col(0);
  Eigen::MatrixXf factors;
  std::vector<int> pivots;
  Factor(a, &factors, &pivots);
  const int saved = omp_get_max_threads();
  for (const LuKernels& kernel : kernels) {
    std::vector<std::uint16_t> half(HalfFactorLayout(n).Size());
    float scale = 0.0f;
    if (kernel.half) {
      ASSERT_TRUE(kernel.to_half(n, factors.data(), half.data(), &scale));
    }
    Eigen::VectorXf x[2] = {b, b}, x_half[2] = {b, b};
    for (int threads = 1; threads <= 2; ++threads) {
      omp_set_num_threads(threads);
      kernel.solve(n, factors.data(), pivots.data(), x[threads - 1].data());
      if (kernel.half)
        kernel.solve_half(n, half.data(), pivots.data(), scale, x_half[threads - 1].data(), {});
    }
    EXPECT_TRUE(x[0] == x[1]) << kernel.name;
    EXPECT_TRUE(x_half[0] == x_half[1]) << kernel.name;
  }
  omp_set_num_threads(saved);
#else
  GTEST_SKIP() << "built without OpenMP";
#endif
}

// The factors in half precision (LuStorage::kHalf): each half kernel against its single-precision
// kernel run on the same rounded factors (widened back, U unscaled), to float rounding; the two
// roundings (AVX-512 and AVX2) give the same halves; and DenseLu's solve against the
// single-precision LU's, within the half rounding's effect (2⁻¹¹ per entry on well-conditioned
// matrices: measured ≤ 1e-3 relative here), on the sizes of TheBlockedSingleSolveMatchesGetrs
// (from 1024 the parallel panels).
TEST(DenseLu, HalfPrecisionFactorsSolveLikeTheirSinglePrecisionValues) {
  std::vector<LuKernels> kernels = KernelsHere();
  kernels.erase(std::remove_if(kernels.begin(), kernels.end(),
                               [](const LuKernels& k) { return !k.half; }),
                kernels.end());
  if (kernels.empty()) GTEST_SKIP() << "neither AVX-512 BW nor F16C here: kHalf keeps floats";
  std::mt19937 rng(12);
  for (const int n : {1, 5, 31, 32, 33, 64, 65, 195, 390, 1023, 1024, 1100, 1153, 2400}) {
    Eigen::MatrixXf a = RandomMatrix<float>(n, &rng) +
                        static_cast<float>(2 * n) * Eigen::MatrixXf::Identity(n, n);
    Eigen::PermutationMatrix<Eigen::Dynamic> shuffle(n);
    shuffle.setIdentity();
    std::shuffle(shuffle.indices().data(), shuffle.indices().data() + n, rng);
    a = shuffle * a * 1e-3f;  // every column pivots; entries far from half precision's 1
    const Eigen::VectorXf b = RandomMatrix<float>(n, &rng).col(0);
    DenseLu<float> single, half;
    ASSERT_TRUE(single.Compute(a));
    ASSERT_TRUE(half.Compute(a, LuStorage::kHalf));
    EXPECT_FALSE(single.half());
    ASSERT_TRUE(half.half());
    Eigen::VectorXf x_single = b, x_half = b, x_then = b;
    single.Solve(&x_single);
    half.Solve(&x_half);
    half.SolveThenPrefetch(&x_then, single);
    EXPECT_EQ(x_then, x_half) << n;
    const float difference = (x_half - x_single).norm() / x_single.norm();
    EXPECT_LT(difference, 1e-3f) << n;
    if (n > 1) {
      EXPECT_GT(difference, 1e-6f) << n;  // the factors were rounded
    }

    Eigen::MatrixXf factors;
    std::vector<int> pivots;
    Factor(a, &factors, &pivots);
    std::vector<std::uint16_t> first;
    for (const LuKernels& kernel : kernels) {
      std::vector<std::uint16_t> rounded(HalfFactorLayout(n).Size());
      float scale = 0.0f;
      ASSERT_TRUE(kernel.to_half(n, factors.data(), rounded.data(), &scale));
      if (first.empty()) first = rounded;
      EXPECT_TRUE(rounded == first) << kernel.name << " " << n;
      Eigen::VectorXf x_kernel = b;
      kernel.solve_half(n, rounded.data(), pivots.data(), scale, x_kernel.data(), {});
      // Prefetching another span along the way (SolveThenPrefetch) changes nothing.
      Eigen::VectorXf x_prefetching = b;
      kernel.solve_half(n, rounded.data(), pivots.data(), scale, x_prefetching.data(),
                        {reinterpret_cast<const char*>(first.data()), 2 * first.size()});
      EXPECT_EQ(x_prefetching, x_kernel) << kernel.name << " " << n;
      // The reference: the same rounded factors, widened, through the single-precision kernel.
      Eigen::MatrixXf widened(n, n);
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          widened(i, j) = Widen(rounded[HalfFactorIndex(n, i, j)]) / (i <= j ? scale : 1.0f);
      Eigen::VectorXf x_reference = b;
      kernel.solve(n, widened.data(), pivots.data(), x_reference.data());
      EXPECT_LT((x_kernel - x_reference).norm(), 1e-5f * x_reference.norm()) << kernel.name << n;
      if (&kernel == &kernels.front()) {
        EXPECT_EQ(x_kernel, x_half) << kernel.name << " " << n;  // DenseLu's is the widest
      }
    }
  }
}

// The half factors' layout (lu_solve_avx512.h, LuPanels): every entry of the factors has its own
// place within the layout's size (none shared, none outside), and ArrangeHalfFactors puts each
// there; column-major below kParallelLuSolve; in tiles, each chunk and diagonal block a run of
// consecutive places, L's blocks before U's. On sizes with a partial last block, a partial last
// chunk, and both.
TEST(DenseLu, HalfFactorLayoutPlacesEveryEntryOnce) {
  for (const int n : {5, kParallelLuSolve - 1, kParallelLuSolve, 1100, 1153, 2400}) {
    const LuPanels layout = HalfFactorLayout(n);
    EXPECT_EQ(layout.tiled, n >= kParallelLuSolve) << n;
    const std::size_t size = layout.Size();
    EXPECT_GE(size, static_cast<std::size_t>(n) * n) << n;
    EXPECT_LE(size, static_cast<std::size_t>(n) * n + 2 * static_cast<std::size_t>(n) * kLuWideBlock)
        << n;
    std::vector<std::uint16_t> column_major(static_cast<std::size_t>(n) * n), arranged(size, 7);
    std::vector<char> taken(size, 0);
    bool inside = true, once = true, placed = true;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        // A value of its own per entry (mod 2¹⁶: checked over the first 65 536 only).
        column_major[static_cast<std::size_t>(i) + static_cast<std::size_t>(j) * n] =
            static_cast<std::uint16_t>((i + j * n) & 0xffff);
      }
    ArrangeHalfFactors(n, column_major.data(), arranged.data());
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const std::size_t at = HalfFactorIndex(n, i, j);
        if (at >= size) {
          inside = false;
          continue;
        }
        once = once && !taken[at];
        taken[at] = 1;
        placed = placed && arranged[at] == static_cast<std::uint16_t>((i + j * n) & 0xffff);
      }
    EXPECT_TRUE(inside) << n;
    EXPECT_TRUE(once) << n;
    EXPECT_TRUE(placed) << n;
    bool rest_zero = true;  // the places no entry takes (the diagonal blocks' unread halves)
    for (std::size_t at = 0; at < size; ++at) rest_zero = rest_zero && (taken[at] || arranged[at] == 0);
    EXPECT_TRUE(rest_zero) << n;
    if (!layout.tiled) {
      EXPECT_EQ(HalfFactorIndex(n, 3, 4), static_cast<std::size_t>(3 + 4 * n));
      continue;
    }
    // Tiled: the chunk of L's first block from row kLuWideBlock, and U's last (top) block's
    // diagonal, where the layout says; a chunk's column follows its previous column.
    EXPECT_EQ(HalfFactorIndex(n, kLuWideBlock, 0), layout.LowerChunk(0, kLuWideBlock, kLuWideBlock));
    EXPECT_EQ(HalfFactorIndex(n, kLuWideBlock + 1, 1),
              HalfFactorIndex(n, kLuWideBlock + 1, 0) + std::min(kLuChunkRows, n - kLuWideBlock));
    EXPECT_EQ(HalfFactorIndex(n, 0, 0), layout.UpperDiagonal(0, n - (n - 1) / kLuWideBlock * kLuWideBlock));
    EXPECT_EQ(HalfFactorIndex(n, 1, 0), layout.LowerDiagonal(0) + 1);
    EXPECT_LT(HalfFactorIndex(n, n - 1, n - 2), HalfFactorIndex(n, 0, n - 1));  // L before U
  }
}

TEST(DenseLu, ReportsASingularMatrix) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Identity(4, 4);
  a(2, 2) = 0.0;
  DenseLu<double> lu;
  EXPECT_FALSE(lu.Compute(a));
}

// From kBlockedLuFrom LuFactor is getrf's blocked algorithm with each step's update over the
// OpenMP threads (dense_lu.cc): against one getrf call, on random matrices (backward error of
// the same size: |A x − b| / (|A| |x|) within 4× of getrf's) and on diagonally dominant ones with
// shuffled rows (every column pivots; the same solution to float rounding, 1e-4); the same bits
// on one thread and two; and the first zero pivot reported as getrf reports it.
TEST(DenseLu, TheBlockedFactorizationMatchesGetrfOnAnyNumberOfThreads) {
  std::mt19937 rng(11);
  for (const int n : {kBlockedLuFrom, 1100, 1500}) {
    const Eigen::MatrixXf random = RandomMatrix<float>(n, &rng);
    const Eigen::MatrixXf dominant = ShuffledDominant(random, &rng);
    const Eigen::VectorXf b = RandomMatrix<float>(n, &rng).col(0);
    for (const Eigen::MatrixXf* a : {&random, &dominant}) {
      Eigen::MatrixXf getrf = *a, blocked[2] = {*a, *a};
      std::vector<int> getrf_pivots(static_cast<size_t>(n)), pivots[2];
      int info = 0;
      sgetrf_(&n, &n, getrf.data(), &n, getrf_pivots.data(), &info);
      ASSERT_EQ(info, 0);
#ifdef _OPENMP
      const int saved = omp_get_max_threads();
#endif
      for (int threads = 1; threads <= 2; ++threads) {
#ifdef _OPENMP
        omp_set_num_threads(threads);
#endif
        pivots[threads - 1].resize(static_cast<size_t>(n));
        LuFactor(n, blocked[threads - 1].data(), pivots[threads - 1].data(), &info);
        ASSERT_EQ(info, 0);
      }
#ifdef _OPENMP
      omp_set_num_threads(saved);
#endif
      EXPECT_TRUE(blocked[0] == blocked[1]) << n;
      EXPECT_EQ(pivots[0], pivots[1]) << n;
      // Solved the same way (getrs) from either set of factors.
      auto solve = [&](const Eigen::MatrixXf& f, const std::vector<int>& p) {
        Eigen::VectorXf x = b;
        const int one = 1;
        sgetrs_("N", &n, &one, f.data(), &n, p.data(), x.data(), &n, &info, 1);
        return x;
      };
      const Eigen::VectorXf x_getrf = solve(getrf, getrf_pivots), x = solve(blocked[0], pivots[0]);
      const float getrf_error = (*a * x_getrf - b).norm() / (a->norm() * x_getrf.norm());
      const float error = (*a * x - b).norm() / (a->norm() * x.norm());
      std::printf("  n = %d %s: backward error %.2e (getrf %.2e)\n", n,
                  a == &random ? "random" : "dominant", error, getrf_error);
      EXPECT_LT(error, 4.0f * getrf_error + 1e-7f) << n;
      if (a == &dominant) {
        EXPECT_LT((x - x_getrf).norm(), 1e-4f * x_getrf.norm()) << n;
      }
    }
  }
  // A zero column past the first panels: the zero pivot where getrf finds it.
  const int n = 1100;
  Eigen::MatrixXf a = RandomMatrix<float>(n, &rng);
  a.col(1050).setZero();
  Eigen::MatrixXf getrf = a;
  std::vector<int> pivots(static_cast<size_t>(n));
  int getrf_info = 0, info = 0;
  sgetrf_(&n, &n, getrf.data(), &n, pivots.data(), &getrf_info);
  LuFactor(n, a.data(), pivots.data(), &info);
  EXPECT_EQ(getrf_info, 1051);
  EXPECT_EQ(info, getrf_info);
  DenseLu<float> lu;
  a = RandomMatrix<float>(n, &rng);
  a.col(1050).setZero();
  EXPECT_FALSE(lu.Compute(a));
}

// OpenBLAS's threads change the last bits with the thread count (measured: dgemv 390 × 390,
// sgetrf 390 … 4000), so the library sets the BLAS to one thread of its own (solver/blas.cc).
extern "C" int openblas_get_num_threads() __attribute__((weak));
TEST(Blas, RunsOnOneThreadOfItsOwn) {
  EXPECT_TRUE(BlasIsSingleThreaded());
  if (openblas_get_num_threads) {
    EXPECT_EQ(openblas_get_num_threads(), 1);
  }
}

// On a CPU with AVX2 and FMA the BLAS must not run its SSE3 fallback (OpenBLAS takes it on CPUs
// newer than itself; solver/blas.cc then chooses by the CPU's features). The user's
// OPENBLAS_CORETYPE stands, whatever it names.
TEST(Blas, DoesNotRunTheOldestKernelsOnANewerCpu) {
  const std::string core = BlasCoreName();
  if (core.empty()) GTEST_SKIP() << "not OpenBLAS";
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) GTEST_SKIP() << "OPENBLAS_CORETYPE set by the user";
#if defined(__x86_64__)
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma"))
    GTEST_SKIP() << "no AVX2 here";
  EXPECT_NE(core, "Prescott");
  // A product and a factorization on the kernels chosen still agree with Eigen's.
  std::mt19937 rng(3);
  const Eigen::MatrixXf a = RandomMatrix<float>(300, &rng);
  DenseLu<float> lu;
  ASSERT_TRUE(lu.Compute(a));
  const Eigen::VectorXf b = RandomMatrix<float>(300, &rng).col(0);
  Eigen::VectorXf x = b;
  lu.Solve(&x);
  EXPECT_LT((a * x - b).norm(), 1e-4f * a.norm() * x.norm());
#else
  GTEST_SKIP() << "not x86-64";
#endif
}

TEST(Blas, ProductsMatchEigen) {
  std::mt19937 rng(9);
  const Eigen::MatrixXd a = RandomMatrix<double>(50, &rng).leftCols(37);
  const Eigen::VectorXd x = RandomMatrix<double>(37, &rng).col(0);
  Eigen::VectorXd y(20);
  GemvRows(a, 13, 20, x.data(), y.data());  // rows 13 … 32
  EXPECT_LT((y - a.middleRows(13, 20) * x).norm(), 1e-13 * y.norm());
  Eigen::VectorXf yf;
  Gemv(a.cast<float>(), x.cast<float>(), &yf);
  EXPECT_LT((yf - a.cast<float>() * x.cast<float>()).norm(), 1e-5f * yf.norm());
}

}  // namespace
}  // namespace stokesrods
