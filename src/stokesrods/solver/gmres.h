// Restarted GMRES with right preconditioning (Saad & Schultz 1986; Saad, Iterative Methods for
// Sparse Linear Systems, 2nd ed., Algorithm 9.5), for operators given only by their products.
//
// Solves A x = b by minimizing |b − A P⁻¹ y| over a Krylov space of A P⁻¹, x = P⁻¹ y. With right
// preconditioning the residual it monitors is the residual of A x = b (not a preconditioned
// one), so the stopping test |b − A x| ≤ tolerance |b| means what it says; A x is carried by the
// Arnoldi relation A Z_k = V_{k+1} H̄_k, so a solve of k iterations costs k products. Arnoldi by modified
// Gram–Schmidt, the least-squares problem by Givens rotations.
#pragma once

#include <functional>

#include "stokesrods/common/types.h"

namespace stokesrods {

/// y = A x (or y = P⁻¹ x); y is resized by the caller to the size of x.
using LinearOperator = std::function<void(const VecX& x, VecX* y)>;

struct GmresOptions {
  double tolerance = 1e-10;  ///< stop when |b − A x| ≤ tolerance |b|  [–]
  double absolute_tolerance = 0.0;  ///< or when |b − A x| ≤ this (units of b)
  /// absolute_tolerance bounds the largest component max_i |(b − A x)_i| instead of the 2-norm:
  /// what a test on every unknown asks (the 2-norm is up to √n times the largest component).
  bool absolute_in_max_norm = false;
  int max_iterations = 200;  ///< products with A, over all restarts
  int restart = 50;          ///< Krylov dimension before a restart
};

struct GmresReport {
  bool converged = false;
  int iterations = 0;        ///< products with A
  double relative_residual = 0.0;  ///< |b − A x| / |b| at the end (A x from the Arnoldi relation)
};

/// Solves A x = b; x holds the initial guess on entry (resized to zero if empty) and the
/// solution on exit; `ax`, if given, receives A x of the returned x (from the Arnoldi relation;
/// exact up to rounding). `preconditioner` may be empty (identity).
GmresReport SolveGmres(const LinearOperator& a, const LinearOperator& preconditioner,
                       const VecX& b, const GmresOptions& options, VecX* x, VecX* ax = nullptr);

/// y = A x and, when `side` is given, side = G x for a second linear map G that the product
/// computes on its way (HydroCoupling: B⁻¹ Sᵀ x, solved for by every product with its
/// capacitance C = h 𝕄 + S B⁻¹ Sᵀ).
using LinearOperatorWithSide = std::function<void(const VecX& x, VecX* y, VecX* side)>;

/// The same solve, also giving `side_of_x` = G x of the returned x: the combination of the
/// products' sides that makes x, so G is never applied to x itself (one application of G less
/// per solve; exact up to rounding). Left empty where no product was taken (x then is the zero
/// initial guess, and G x = 0).
GmresReport SolveGmres(const LinearOperatorWithSide& a, const LinearOperator& preconditioner,
                       const VecX& b, const GmresOptions& options, VecX* x, VecX* ax,
                       VecX* side_of_x);

}  // namespace stokesrods
