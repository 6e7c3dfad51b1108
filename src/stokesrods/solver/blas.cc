#include "stokesrods/solver/blas.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "stokesrods/common/parallel.h"

extern "C" {
void sgemv_(const char* trans, const int* m, const int* n, const float* alpha, const float* a,
            const int* lda, const float* x, const int* incx, const float* beta, float* y,
            const int* incy, std::size_t trans_len);
void dgemv_(const char* trans, const int* m, const int* n, const double* alpha, const double* a,
            const int* lda, const double* x, const int* incx, const double* beta, double* y,
            const int* incy, std::size_t trans_len);
void sgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k,
            const float* alpha, const float* a, const int* lda, const float* b, const int* ldb,
            const float* beta, float* c, const int* ldc, std::size_t, std::size_t);
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k,
            const double* alpha, const double* a, const int* lda, const double* b, const int* ldb,
            const double* beta, double* c, const int* ldc, std::size_t, std::size_t);
}

// OpenBLAS's own threads split its products and factorizations differently for each thread
// count, so their results would depend on it in the last bits (measured: dgemv of 390 × 390, sgetrf
// of 390 … 4000 differ between 1 and 2 threads), and a run could not resume bit for bit on
// another thread count (tests/reliability/kill_resume.py). The BLAS therefore runs on one thread
// of its own; our parallelism is OpenMP over independent pieces. Weak: absent with another BLAS.
extern "C" void openblas_set_num_threads(int) __attribute__((weak));

// OpenBLAS built for many CPUs (Debian's, DYNAMIC_ARCH) picks its kernels by the CPU's family and
// model, and falls back to its oldest x86-64 ones ("Prescott": SSE3) on a model it does not know:
// Debian 12's 0.3.21 does not know Intel's Xeons from Sapphire Rapids on (seen: family 6 model
// 207, an Emerald Rapids, with AVX-512). There the FMM's translations (dgemm) and the
// preconditioners' LU factorizations (sgetrf) run 3–4× slower than they could (perf on 100
// helices: dgemm and sgemm 11.7 % of a step with the fallback, 2.3 % with SkylakeX's kernels).
// OpenBLAS's own remedy is the environment variable OPENBLAS_CORETYPE, read when it loads, before
// main(); so when it is unset and the fallback was taken on a CPU with AVX-512 (or AVX2 and FMA),
// the variable is set here and OpenBLAS's kernel table chosen again by its own functions. Weak:
// with another BLAS, or an OpenBLAS without them, nothing happens.
extern "C" char* openblas_get_corename(void) __attribute__((weak));
extern "C" void gotoblas_dynamic_init(void) __attribute__((weak));
extern "C" void gotoblas_dynamic_quit(void) __attribute__((weak));

namespace stokesrods {
namespace {

const char* BetterBlasCore() {
#if defined(__x86_64__)
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl"))
    return "SkylakeX";
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "Haswell";
#endif
  return nullptr;
}

void ChooseBlasKernels() {
  if (!openblas_get_corename || !gotoblas_dynamic_init || !gotoblas_dynamic_quit) return;
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) return;  // the user's choice stands
  const char* core = openblas_get_corename();
  if (core == nullptr || std::strcmp(core, "Prescott") != 0) return;
  const char* better = BetterBlasCore();
  if (better == nullptr) return;
  setenv("OPENBLAS_CORETYPE", better, 0);
  gotoblas_dynamic_quit();
  gotoblas_dynamic_init();
  unsetenv("OPENBLAS_CORETYPE");  // read by the init only: the environment stays the user's
}

const bool kBlasOnOneThread = [] {
  ChooseBlasKernels();
  if (openblas_set_num_threads) openblas_set_num_threads(1);
  return true;
}();

}  // namespace

bool BlasIsSingleThreaded() { return kBlasOnOneThread; }

std::string BlasCoreName() {
  if (!openblas_get_corename) return "";
  const char* core = openblas_get_corename();
  return core != nullptr ? core : "";
}

void Gemm(int m, int n, int k, float alpha, const float* a, int lda, const float* b, int ldb,
          float beta, float* c, int ldc) {
  sgemm_("N", "N", &m, &n, &k, &alpha, a, &lda, b, &ldb, &beta, c, &ldc, 1, 1);
}
void Gemm(int m, int n, int k, double alpha, const double* a, int lda, const double* b, int ldb,
          double beta, double* c, int ldc) {
  dgemm_("N", "N", &m, &n, &k, &alpha, a, &lda, b, &ldb, &beta, c, &ldc, 1, 1);
}

void Gemv(const Eigen::MatrixXf& a, const Eigen::VectorXf& x, Eigen::VectorXf* y) {
  const Eigen::Index m = a.rows();
  y->resize(m);
  constexpr Eigen::Index kRows = 1024;  // each block's rows: the same sums on any thread count
  const int blocks = static_cast<int>((m + kRows - 1) / kRows);
  ForEachStatic(blocks, blocks > 2, [&](int b) {
    const Eigen::Index first = b * kRows;
    GemvRows(a, first, std::min(kRows, m - first), x.data(), y->data() + first);
  });
}


namespace {

void Gemv(int m, int n, const float* a, int lda, const float* x, float* y) {
  const float alpha = 1.0f, beta = 0.0f;
  const int one = 1;
  sgemv_("N", &m, &n, &alpha, a, &lda, x, &one, &beta, y, &one, 1);
}
void Gemv(int m, int n, const double* a, int lda, const double* x, double* y) {
  const double alpha = 1.0, beta = 0.0;
  const int one = 1;
  dgemv_("N", &m, &n, &alpha, a, &lda, x, &one, &beta, y, &one, 1);
}

template <typename Scalar>
void Rows(const Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>& a, Eigen::Index first,
          Eigen::Index rows, const Scalar* x, Scalar* y) {
  if (rows == 0) return;
  if (a.cols() == 0) {
    std::fill(y, y + rows, Scalar(0));
    return;
  }
  Gemv(static_cast<int>(rows), static_cast<int>(a.cols()), a.data() + first,
       static_cast<int>(a.rows()), x, y);
}

}  // namespace

void GemvRows(const Eigen::MatrixXd& a, Eigen::Index first, Eigen::Index rows, const double* x,
              double* y) {
  Rows(a, first, rows, x, y);
}

void GemvRows(const Eigen::MatrixXf& a, Eigen::Index first, Eigen::Index rows, const float* x,
              float* y) {
  Rows(a, first, rows, x, y);
}

}  // namespace stokesrods
