// y = A x by the BLAS (OpenBLAS: vectorized for the CPU at hand). The build targets baseline
// x86-64, where Eigen's own products use SSE2 only; these are the products that matter.
#pragma once

#include <string>

#include <Eigen/Core>

namespace stokesrods {

/// True once the BLAS is set to one thread of its own (done when this library is loaded; see
/// blas.cc: results must not depend on the thread count). Callers of the BLAS reference it so
/// that the setting is linked in.
bool BlasIsSingleThreaded();
/// OpenBLAS's kernel set in use ("SkylakeX", "Haswell", "Zen", …; empty with another BLAS). On a
/// CPU it does not know, OpenBLAS would take its SSE3 fallback; blas.cc then chooses by the CPU's
/// features, unless OPENBLAS_CORETYPE is set.
std::string BlasCoreName();

/// c = alpha a b + beta c by the BLAS's gemm, column-major: a m × k (leading dimension lda), b
/// k × n (ldb), c m × n (ldc). The one declaration of sgemm/dgemm in the project.
void Gemm(int m, int n, int k, float alpha, const float* a, int lda, const float* b, int ldb,
          float beta, float* c, int ldc);
void Gemm(int m, int n, int k, double alpha, const double* a, int lda, const double* b, int ldb,
          double beta, double* c, int ldc);

/// y = A x (y resized), rows in blocks over the OpenMP threads (the BLAS itself runs on one).
void Gemv(const Eigen::MatrixXf& a, const Eigen::VectorXf& x, Eigen::VectorXf* y);
/// y = A x for a block of rows of a column-major matrix: rows [first, first + rows) of `a`.
void GemvRows(const Eigen::MatrixXd& a, Eigen::Index first, Eigen::Index rows, const double* x,
              double* y);
void GemvRows(const Eigen::MatrixXf& a, Eigen::Index first, Eigen::Index rows, const float* x,
              float* y);

/// The kernels of GemvRowsMixed: the widest vectors the CPU has (AVX-512, else AVX2 with FMA, else
/// the plain loop), or for tests AVX2 even where AVX-512 is present, or the plain loop.
enum class MixedGemvPath { kWidest, kAvx2, kPortable };

/// y = A x for rows [first, first + rows) of a single-precision matrix, with x, y and the sums in
/// double (gemv_mixed.cc). Each row's sum in one fixed order: independent of how rows are split
/// over threads.
void GemvRowsMixed(const Eigen::MatrixXf& a, Eigen::Index first, Eigen::Index rows, const double* x,
                   double* y, MixedGemvPath path = MixedGemvPath::kWidest);

}  // namespace stokesrods
