#include "stokesrods/sim/elastic_assembly.h"

#include "stokesrods/elastic/bending.h"
#include "stokesrods/elastic/stretching.h"
#include "stokesrods/elastic/twisting.h"

namespace stokesrods {

double AddElasticForces(const RodModel& rod, const VecX& q, const RodFrames& frames, VecX* force,
                        BandedMatrix* hessian) {
  const int n = rod.num_nodes();
  const int o = rod.dof_offset;
  auto x = [&](int i) { return Vec3(q.segment<3>(o + NodeDof(i))); };
  const bool want_gradient = force != nullptr || hessian != nullptr;
  double energy = 0.0;

  Vec6 g6;
  Mat6 h6;
  for (int j = 0; j + 1 < n; ++j) {  // stretching of edge j: DOFs (x_j, x_{j+1})
    const StretchingParams p{rod.axial_stiffness, rod.rest_edge_length(j)};
    energy += StretchingEnergy(p, x(j), x(j + 1), want_gradient ? &g6 : nullptr,
                               hessian ? &h6 : nullptr);
    const int a = NodeDof(j), b = NodeDof(j + 1);
    if (force) {
      force->segment<3>(o + a) -= g6.head<3>();
      force->segment<3>(o + b) -= g6.tail<3>();
    }
    if (hessian) {
      hessian->AddBlock(a, h6.topLeftCorner<3, 3>());
      hessian->AddBlock(b, h6.bottomRightCorner<3, 3>());
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
          (*hessian)(a + r, b + c) += h6(r, 3 + c);
          (*hessian)(b + r, a + c) += h6(3 + r, c);
        }
    }
  }

  // Bending and twisting at node i share the curvature of the stencil (DOFs 4(i−1) … 4(i+1)+2)
  // and are summed in the edge variables, then mapped to the stencil once.
  Vec8 bend_g, twist_g;
  Mat8 bend_h, twist_h;
  for (int i = 1; i + 1 < n; ++i) {
    const double dl = rod.rest_voronoi_length(i);
    const double theta0 = q(o + TwistDof(i - 1)), theta1 = q(o + TwistDof(i));
    const StencilCurvature c = CalcStencilCurvature(x(i) - x(i - 1), x(i + 1) - x(i), want_gradient);
    const BendingParams bp{rod.bending_stiffness / dl, rod.rest_curvature[i]};
    energy += BendingEdgeEnergy(bp, c, frames.frames[i - 1], frames.frames[i], theta0, theta1,
                                want_gradient ? &bend_g : nullptr, hessian ? &bend_h : nullptr);
    const TwistingParams tp{rod.twisting_stiffness / dl, rod.rest_twist(i)};
    energy += TwistingEdgeEnergy(tp, c, theta0, theta1, frames.reference_twist(i),
                                 want_gradient ? &twist_g : nullptr, hessian ? &twist_h : nullptr);
    const int first = NodeDof(i - 1);  // the stencil is 11 consecutive DOFs
    if (force) force->segment<11>(o + first) -= EdgeToStencilGradient(bend_g + twist_g);
    if (hessian) hessian->AddBlock(first, EdgeToStencilHessian(bend_h + twist_h));
  }
  return energy;
}

}  // namespace stokesrods
