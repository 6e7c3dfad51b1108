#include "stokesrods/solver/gmres.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace stokesrods {

GmresReport SolveGmres(const LinearOperator& a, const LinearOperator& preconditioner,
                       const VecX& b, const GmresOptions& options, VecX* x, VecX* ax) {
  const LinearOperatorWithSide product = [&](const VecX& in, VecX* out, VecX*) { a(in, out); };
  return SolveGmres(product, preconditioner, b, options, x, ax, nullptr);
}

GmresReport SolveGmres(const LinearOperatorWithSide& a, const LinearOperator& preconditioner,
                       const VecX& b, const GmresOptions& options, VecX* x, VecX* ax,
                       VecX* side_of_x) {
  const Eigen::Index n = b.size();
  if (x->size() != n) x->setZero(n);
  GmresReport report;
  if (side_of_x) side_of_x->resize(0);
  const double b_norm = b.norm();
  if (b_norm == 0.0) {
    x->setZero();
    if (ax) ax->setZero(n);
    report.converged = true;
    return report;
  }
  const int m = std::max(1, options.restart);
  MatX v(n, m + 1);             // Arnoldi basis
  MatX z(n, m);                 // preconditioned directions P⁻¹ v_j (flexible form: no re-apply)
  // Column k of both is zeroed at iteration k, when it is first written (not the whole (m + 1) × m
  // at each cycle: with m = 50 that was 80 KB of zeros per solve, for 1–5 columns used).
  MatX hess(m + 1, m);
  MatX hess_raw(m + 1, m);  // H̄ before the rotations: A Z_k = V_{k+1} H̄_k
  VecX cs(m), sn(m), g(m + 1);
  VecX w(n), r(n);
  auto apply_p = [&](const VecX& in, VecX* out) {
    if (preconditioner) preconditioner(in, out); else *out = in;
  };

  // y of the least-squares problem after k iterations (k × k upper triangular, rotated).
  auto least_squares = [&](int k) {
    VecX y = g.head(k);
    for (int i = k - 1; i >= 0; --i) {
      for (int j = i + 1; j < k; ++j) y(i) -= hess(i, j) * y(j);
      y(i) = hess(i, i) != 0.0 ? y(i) / hess(i, i) : 0.0;
    }
    return y;
  };
  // The absolute test in the norm it is asked in (the 2-norm, or the largest component).
  auto meets_absolute = [&](const VecX& residual, double residual_norm, double margin) {
    if (options.absolute_tolerance <= 0.0) return false;
    if (!options.absolute_in_max_norm) return residual_norm <= margin * options.absolute_tolerance;
    return residual.lpNorm<Eigen::Infinity>() <= margin * options.absolute_tolerance;
  };

  VecX arnoldi_product;         // V_{k+1} H̄_k y, the change of A x over a cycle
  MatX sides;                   // G z_j, as the products give them (side_of_x only)
  VecX side;
  VecX product = VecX::Zero(n);  // A x
  if (!x->isZero(0.0)) a(*x, &product, side_of_x);
  r = b - product;
  double r_norm = r.norm();
  const double sqrt_n = std::sqrt(static_cast<double>(n));
  while (true) {
    report.relative_residual = r_norm / b_norm;
    report.converged = report.relative_residual <= options.tolerance ||
                       meets_absolute(r, r_norm, 1.0);
    if (report.converged || report.iterations >= options.max_iterations) {
      if (ax) *ax = product;
      return report;
    }
    v.col(0) = r / r_norm;
    g.setZero();
    bool have_arnoldi_product = false;  // V_{k+1} H̄_k y of the last trial residual
    g(0) = r_norm;
    int k = 0;
    for (; k < m && report.iterations < options.max_iterations; ++k) {
      VecX zk(n);
      apply_p(v.col(k), &zk);
      z.col(k) = zk;
      a(zk, &w, side_of_x ? &side : nullptr);
      ++report.iterations;
      hess.col(k).setZero();
      if (side_of_x) {
        if (sides.cols() != m) sides.resize(side.size(), m);
        sides.col(k) = side;
      }
      for (int i = 0; i <= k; ++i) {  // modified Gram–Schmidt
        hess(i, k) = v.col(i).dot(w);
        w -= hess(i, k) * v.col(i);
      }
      hess(k + 1, k) = w.norm();
      if (hess(k + 1, k) > 0.0) v.col(k + 1) = w / hess(k + 1, k);
      hess_raw.col(k).setZero();  // below H̄'s subdiagonal: read by the products with it
      hess_raw.col(k).head(k + 2) = hess.col(k).head(k + 2);
      for (int i = 0; i < k; ++i) {  // previous rotations on the new column
        const double t = cs(i) * hess(i, k) + sn(i) * hess(i + 1, k);
        hess(i + 1, k) = -sn(i) * hess(i, k) + cs(i) * hess(i + 1, k);
        hess(i, k) = t;
      }
      const double denom = std::hypot(hess(k, k), hess(k + 1, k));
      cs(k) = denom > 0.0 ? hess(k, k) / denom : 1.0;
      sn(k) = denom > 0.0 ? hess(k + 1, k) / denom : 0.0;
      hess(k, k) = denom;
      hess(k + 1, k) = 0.0;
      g(k + 1) = -sn(k) * g(k);
      g(k) = cs(k) * g(k);
      // |g(k+1)| is the residual norm of the least-squares problem (in exact arithmetic). Half
      // the tolerance here, so that the residual formed after the cycle meets the whole of it
      // (the basis' loss of orthogonality parts the two).
      const double estimate = std::abs(g(k + 1));
      bool done = estimate <= 0.5 * options.tolerance * b_norm || hess(k, k) == 0.0;
      if (!done && options.absolute_in_max_norm) {
        // The largest component is at least the 2-norm / √n: only then is the residual worth
        // forming (O(n k), no product), b − A x − V_{k+2} H̄ y. That is the residual the cycle
        // then forms (the same y, the same sum, to rounding), not an estimate of it, so it is
        // held to the whole tolerance, as the test at the top of the loop holds it (until
        // session 36 to half: GMRES then ran on for a product in 5–30 % of the solves,
        // lattice100 3.575 → 3.25 products per step, ring10 3.05 → 2.8).
        if (estimate <= sqrt_n * options.absolute_tolerance) {
          const VecX y = least_squares(k + 1);
          arnoldi_product = v.leftCols(k + 2) * (hess_raw.topLeftCorner(k + 2, k + 1) * y);
          done = have_arnoldi_product = meets_absolute(r - arnoldi_product, estimate, 1.0);
        }
      } else if (!done) {
        done = meets_absolute(r, estimate, 0.5);
      }
      if (done) {
        ++k;
        break;
      }
    }
    // Back substitution for y (k × k upper triangular), x += Z y.
    const VecX y = least_squares(k);
    *x += z.leftCols(k) * y;
    if (side_of_x) {
      if (side_of_x->size() == 0) side_of_x->setZero(sides.rows());
      *side_of_x += sides.leftCols(k) * y;
    }
    // A x from the Arnoldi relation, A (x + Z y) = A x + V_{k+1} H̄_k y: no extra product, and the
    // residual b − A x is formed explicitly (its norm equals the least-squares estimate up to the
    // basis' loss of orthogonality, which a restart then corrects).
    // (Formed for the trial residual already when the cycle ended by it: the same y, the same
    // columns, the same bits.)
    if (!have_arnoldi_product)
      arnoldi_product = v.leftCols(k + 1) * (hess_raw.topLeftCorner(k + 1, k) * y);
    product += arnoldi_product;
    r = b - product;
    r_norm = r.norm();
  }
}

}  // namespace stokesrods
