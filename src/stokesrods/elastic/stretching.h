// Stretching energy of one edge (paper eq. 5a with the strain of eq. 1 read as |e|/|ē| − 1).
#pragma once

#include "stokesrods/common/types.h"

namespace stokesrods {

struct StretchingParams {
  double axial_stiffness;  ///< EA [N]
  double rest_length;      ///< |ē| [m], > 0
};

/// E = ½ EA |ē| (|e|/|ē| − 1)²  [J], e = x1 − x0.
/// Local DOF order (x0, x1). Gradient and Hessian are written only when asked for.
double StretchingEnergy(const StretchingParams& p, const Vec3& x0, const Vec3& x1,
                        Vec6* gradient = nullptr, Mat6* hessian = nullptr);

}  // namespace stokesrods
