// The vectorized inner loop shared by the Stokeslet sums (stokeslet_sum.cc, fmm_sum.cc): sources
// as the columns (x, y, z, ε², g_x, g_y, g_z) of an S × 7 matrix so that the loop over sources
// vectorizes (AVX-512/AVX2 clones chosen at run time; stokeslet_sum.cc is built with
// -fno-math-errno). Internal to the fluid module.
#pragma once

#include "stokesrods/common/types.h"

namespace stokesrods {

struct SourceColumns {
  const double *x, *y, *z, *e2, *gx, *gy, *gz;
};

/// The columns of an S × 7 source matrix.
SourceColumns Columns(const MatX& src);

/// The S × 7 source matrix of the points and blob sizes, strengths zero.
MatX SourceMatrix(const Matrix3X& sources, const VecX& regularization);

/// w += Σ_{s ∈ [begin, end)} S_ε_s(x − y_s) g_s, with
/// S_ε(r) g = (1/R + ε²/R³) g + (r·g) r / R³,  R² = |r|² + ε²  (ε = 0: the singular Stokeslet;
/// the caller keeps x off the sources then).
void AddPointSum(const SourceColumns& c, Eigen::Index begin, Eigen::Index end, const double* x,
                 double* w);

}  // namespace stokesrods
