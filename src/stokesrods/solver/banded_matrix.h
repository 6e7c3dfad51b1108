// A square banded matrix with its LU factorization (partial pivoting, LAPACK's band storage).
//
// The Jacobian of one discrete rod couples only DOFs within one bending stencil
// (x_{i−1}, θ^{i−1}, x_i, θ^i, x_{i+1}: 11 consecutive entries of q), so its half bandwidth is 10
// and a solve costs O(N) for N nodes. The LU is taken without row interchanges where that is
// stable (positive pivots, no growth: the symmetric part positive definite, as the rods' Newton
// matrices are at a time step's mass term), at half the cost; else with partial pivoting, which
// keeps the solve correct when the matrix is indefinite (compressed or buckling rods in a static
// solve).
#pragma once

#include <vector>

#include "stokesrods/common/types.h"

namespace stokesrods {

class BandedMatrix;

/// Solves matrices[k] x = rhs[k] in place (one right-hand side each, `count` systems): two at a
/// time where they share size, bandwidth and pivoting, their rows in turn (the CPU overlaps the
/// two chains of dependent updates); bit for bit each matrix's own Solve.
void SolveEach(const BandedMatrix* const* matrices, double* const* rhs, int count);

class BandedMatrix {
 public:
  BandedMatrix() = default;
  BandedMatrix(int size, int half_bandwidth) { Resize(size, half_bandwidth); }

  void Resize(int size, int half_bandwidth);
  void SetZero();

  int size() const { return n_; }
  int half_bandwidth() const { return kd_; }

  /// Entry (i, j); precondition |i − j| ≤ half_bandwidth.
  double& operator()(int i, int j) { return ab_[Index(i, j)]; }
  double operator()(int i, int j) const { return ab_[Index(i, j)]; }

  /// Adds the dense block `block` with its top-left corner at (first, first).
  template <typename Derived>
  void AddBlock(int first, const Eigen::MatrixBase<Derived>& block) {
    // A column of the block is a contiguous run of the band storage (Index below): added as a
    // vector (element by element, the compiler could not rule out that it aliases the block).
    using Column = Eigen::Matrix<double, Derived::RowsAtCompileTime, 1>;
    for (int c = 0; c < block.cols(); ++c)
      Eigen::Map<Column>(ab_.data() + Index(first, first + c), block.rows()) += block.col(c);
  }

  /// Replaces row and column k by those of the identity (a fixed DOF).
  void FixDof(int k);

  /// y += A x.
  void MultiplyAdd(const VecX& x, VecX* y) const;

  /// Dense copy (for tests and small debugging).
  MatX ToDense() const;

  /// LU-factorizes in place; returns false if the matrix is singular. After this the
  /// entries are the factors: only Solve may be used until the next SetZero.
  bool Factorize();
  /// Whether the last Factorize interchanged rows (partial pivoting) or needed none.
  bool pivoted() const { return pivoted_; }
  /// Solves A x = b in place for one or more right-hand sides (columns of b).
  void Solve(double* b, int num_rhs) const;
  void Solve(VecX* b) const { Solve(b->data(), 1); }
  void Solve(MatX* b) const { Solve(b->data(), static_cast<int>(b->cols())); }

 private:
  // LAPACK general band storage with kl = ku = kd and kd extra rows for the fill of pivoting:
  // A(i, j) is stored at ab_[(2kd + i − j) + j · ldab], ldab = 3kd + 1.
  int Index(int i, int j) const { return (2 * kd_ + i - j) + j * ldab_; }
  // Solve for many right-hand sides at once, on a row-major copy (vectorizes across them).
  void SolveManyRows(double* b, int num_rhs) const;
  friend void SolveEach(const BandedMatrix* const*, double* const*, int);

  int n_ = 0;
  int kd_ = 0;
  int ldab_ = 1;
  std::vector<double> ab_;
  std::vector<int> pivots_;
  std::vector<double> inverse_diagonal_;  // 1/U(j, j) after Factorize
  std::vector<double> original_;  // A while Factorize tries it without pivoting
  bool factorized_ = false;
  bool pivoted_ = true;  // the factors hold row interchanges (U of bandwidth 2kd)
};

}  // namespace stokesrods
