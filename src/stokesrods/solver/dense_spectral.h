// Spectral decompositions of dense matrices by LAPACK (OpenBLAS): the thin singular value
// decomposition (dgesdd, divide and conquer) and the pseudo-inverse built on it, for the FMM's
// translation operators; the eigenvalues of a general matrix (dgeev), for the explicit scheme's
// stable step, and of a symmetric one (dsyevd), for the tests' spectra. None runs in the time
// step. Eigen's BDCSVD and EigenSolver do the same, but their instantiations took 50–80 s of
// compile time per file under the sanitizers (docs/reliability.md, "The build on the AMD host").
#pragma once

#include <complex>

#include <Eigen/Core>

namespace stokesrods {

/// a (m × n) = U diag(s) Vᵀ with k = min(m, n): U m × k and V n × k with orthonormal columns, s
/// (k) non-negative and non-increasing. False if LAPACK's iteration did not converge (the outputs
/// are then unspecified).
bool ThinSvd(const Eigen::MatrixXd& a, Eigen::MatrixXd* u, Eigen::VectorXd* s,
             Eigen::MatrixXd* v);

/// The pseudo-inverse V diag(1/s) Uᵀ (n × m), the singular values at or below cutoff · s_max
/// dropped (0 ≤ cutoff < 1). Stops the program if the SVD fails (it converges for any finite a).
Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& a, double cutoff);

/// The eigenvalues of a symmetric matrix (its lower triangle is read) in increasing order, by
/// dsyevd. Stops the program if LAPACK's iteration fails.
Eigen::VectorXd SymmetricEigenvalues(const Eigen::MatrixXd& a);

/// The eigenvalues of a square matrix, complex conjugate pairs next to each other, in no
/// particular order. Stops the program if LAPACK's QR iteration fails.
Eigen::VectorXcd Eigenvalues(const Eigen::MatrixXd& a);

}  // namespace stokesrods
