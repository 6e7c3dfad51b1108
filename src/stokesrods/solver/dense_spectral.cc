#include "stokesrods/solver/dense_spectral.h"

#include <algorithm>
#include <vector>

#include "stokesrods/common/assert.h"
#include "stokesrods/solver/blas.h"

extern "C" {
void dgesdd_(const char* jobz, const int* m, const int* n, double* a, const int* lda, double* s,
             double* u, const int* ldu, double* vt, const int* ldvt, double* work,
             const int* lwork, int* iwork, int* info, std::size_t jobz_len);
void dsyevd_(const char* jobz, const char* uplo, const int* n, double* a, const int* lda,
             double* w, double* work, const int* lwork, int* iwork, const int* liwork, int* info,
             std::size_t jobz_len, std::size_t uplo_len);
void dgeev_(const char* jobvl, const char* jobvr, const int* n, double* a, const int* lda,
            double* wr, double* wi, double* vl, const int* ldvl, double* vr, const int* ldvr,
            double* work, const int* lwork, int* info, std::size_t jobvl_len,
            std::size_t jobvr_len);
}

namespace stokesrods {

bool ThinSvd(const Eigen::MatrixXd& a, Eigen::MatrixXd* u, Eigen::VectorXd* s,
             Eigen::MatrixXd* v) {
  (void)BlasIsSingleThreaded();  // one BLAS thread: the same bits on any thread count
  const int m = static_cast<int>(a.rows()), n = static_cast<int>(a.cols());
  const int k = std::min(m, n);
  u->resize(m, k);
  s->resize(k);
  Eigen::MatrixXd vt(k, n);
  if (k == 0) {
    v->resize(n, 0);
    return true;
  }
  Eigen::MatrixXd work_a = a;  // overwritten
  std::vector<int> iwork(8 * static_cast<std::size_t>(k));
  const int lda = m, ldu = m, ldvt = k;
  int info = 0, lwork = -1;
  double size = 0.0;  // the workspace query
  dgesdd_("S", &m, &n, work_a.data(), &lda, s->data(), u->data(), &ldu, vt.data(), &ldvt, &size,
          &lwork, iwork.data(), &info, 1);
  SR_ASSERT(info == 0, "dgesdd: the workspace query failed");
  lwork = static_cast<int>(size);
  std::vector<double> work(static_cast<std::size_t>(std::max(lwork, 1)));
  dgesdd_("S", &m, &n, work_a.data(), &lda, s->data(), u->data(), &ldu, vt.data(), &ldvt,
          work.data(), &lwork, iwork.data(), &info, 1);
  SR_ASSERT(info >= 0, "dgesdd: an argument was invalid");
  *v = vt.transpose();
  return info == 0;
}

Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& a, double cutoff) {
  Eigen::MatrixXd u, v;
  Eigen::VectorXd s;
  const bool converged = ThinSvd(a, &u, &s, &v);
  SR_ASSERT(converged, "PseudoInverse: the SVD did not converge");
  for (Eigen::Index i = 0; i < s.size(); ++i)  // V diag(1/s) Uᵀ, column by column of V
    v.col(i) *= s[i] > cutoff * s[0] ? 1.0 / s[i] : 0.0;
  return v * u.transpose();
}

Eigen::VectorXd SymmetricEigenvalues(const Eigen::MatrixXd& a) {
  SR_ASSERT(a.rows() == a.cols(), "SymmetricEigenvalues: the matrix must be square");
  (void)BlasIsSingleThreaded();
  const int n = static_cast<int>(a.rows());
  Eigen::VectorXd w(n);
  if (n == 0) return w;
  Eigen::MatrixXd work_a = a;  // overwritten
  double size = 0.0;
  int isize = 0, info = 0, lwork = -1, liwork = -1;
  dsyevd_("N", "L", &n, work_a.data(), &n, w.data(), &size, &lwork, &isize, &liwork, &info, 1, 1);
  SR_ASSERT(info == 0, "dsyevd: the workspace query failed");
  lwork = static_cast<int>(size);
  liwork = std::max(isize, 1);
  std::vector<double> work(static_cast<std::size_t>(std::max(lwork, 1)));
  std::vector<int> iwork(static_cast<std::size_t>(liwork));
  dsyevd_("N", "L", &n, work_a.data(), &n, w.data(), work.data(), &lwork, iwork.data(), &liwork,
          &info, 1, 1);
  SR_ASSERT(info == 0, "dsyevd: the iteration did not converge");
  return w;
}

Eigen::VectorXcd Eigenvalues(const Eigen::MatrixXd& a) {
  SR_ASSERT(a.rows() == a.cols(), "Eigenvalues: the matrix must be square");
  (void)BlasIsSingleThreaded();
  const int n = static_cast<int>(a.rows());
  if (n == 0) return Eigen::VectorXcd(0);
  Eigen::MatrixXd work_a = a;  // overwritten
  Eigen::VectorXd wr(n), wi(n);
  double unused = 0.0, size = 0.0;
  const int one = 1;
  int info = 0, lwork = -1;
  dgeev_("N", "N", &n, work_a.data(), &n, wr.data(), wi.data(), &unused, &one, &unused, &one,
         &size, &lwork, &info, 1, 1);
  SR_ASSERT(info == 0, "dgeev: the workspace query failed");
  lwork = static_cast<int>(size);
  std::vector<double> work(static_cast<std::size_t>(std::max(lwork, 1)));
  dgeev_("N", "N", &n, work_a.data(), &n, wr.data(), wi.data(), &unused, &one, &unused, &one,
         work.data(), &lwork, &info, 1, 1);
  SR_ASSERT(info == 0, "dgeev: the QR iteration did not converge");
  Eigen::VectorXcd lambda(n);
  for (int i = 0; i < n; ++i) lambda[i] = {wr[i], wi[i]};
  return lambda;
}

}  // namespace stokesrods
