#include "stokesrods/elastic/stretching.h"

#include "stokesrods/common/assert.h"

namespace stokesrods {

// Strain ε = |e|/|ē| − 1. The paper's eq. 1 prints |ē|/|e| − 1, a transcription slip: DER (Bergou
// et al. 2008, 2010) uses the engineering strain |e|/|ē| − 1, which with eq. 5a gives the axial
// force EA ε along the edge (the printed form would stiffen without bound in compression and
// saturate in tension).
//
// With l = |e|, t = e/l, l̄ = |ē|:
//   E = ½ EA l̄ ε²,   ∂E/∂e = EA ε t,   ∂²E/∂e² = (EA/l̄) t tᵀ + (EA ε / l) (I − t tᵀ),
// and ∂/∂x0 = −∂/∂e, ∂/∂x1 = +∂/∂e.
double StretchingEnergy(const StretchingParams& p, const Vec3& x0, const Vec3& x1, Vec6* gradient,
                        Mat6* hessian) {
  SR_ASSERT(p.rest_length > 0.0, "stretching: rest_length must be > 0");
  SR_ASSERT(p.axial_stiffness >= 0.0, "stretching: axial_stiffness must be >= 0");
  const Vec3 e = x1 - x0;
  const double length = e.norm();
  SR_ASSERT(length > 0.0, "stretching: zero-length edge");
  const Vec3 t = e / length;
  const double strain = length / p.rest_length - 1.0;
  if (gradient) {
    const Vec3 g = p.axial_stiffness * strain * t;
    *gradient << -g, g;
  }
  if (hessian) {
    const Mat3 tt = t * t.transpose();
    const Mat3 h = (p.axial_stiffness / p.rest_length) * tt +
                   (p.axial_stiffness * strain / length) * (Mat3::Identity() - tt);
    hessian->topLeftCorner<3, 3>() = h;
    hessian->bottomRightCorner<3, 3>() = h;
    hessian->topRightCorner<3, 3>() = -h;
    hessian->bottomLeftCorner<3, 3>() = -h;
  }
  return 0.5 * p.axial_stiffness * p.rest_length * strain * strain;
}

}  // namespace stokesrods
