// The bending and twisting of all the stencils of a rod at once, several stencils per vector
// (elastic/stencil_lanes.h): AVX-512 (eight lanes of doubles) or AVX2 with FMA (four) where the
// CPU has them, else one stencil at a time. The rod's assembly (sim/elastic_assembly.cc) gathers
// the inputs by columns and scatters the results into its force and banded Jacobian.
#pragma once

#include <vector>

namespace stokesrods {

/// The inputs of `count` stencils by columns. Stencil s sits between edges s and s + 1: the edge
/// columns hold count + 1 entries, the stencil columns count.
struct StencilColumns {
  const double* edge[3] = {};  ///< edge vectors e = x_{j+1} − x_j
  const double* length = nullptr;  ///< |e|
  const double* m1[3] = {};    ///< material directors m1, m2 of the edges
  const double* m2[3] = {};
  const double* curvature_binormal[3] = {};  ///< κb = 2 e0 × e1 / D of the stencil
  const double* denominator = nullptr;       ///< D = |e0||e1| + e0·e1
  const double* excess[2] = {};              ///< κ⁽¹⁾ − κ̄⁽¹⁾, κ⁽²⁾ − κ̄⁽²⁾
  const double* bend = nullptr;              ///< EI / Δl of the stencil's node
  const double* twist_stiffness = nullptr;   ///< GJ / Δl
  const double* twist = nullptr;             ///< τ − τ̄
};

/// Per stencil: its energy, its gradient in the stencil DOFs (x0, θ0, x1, θ1, x2) (11 values) and,
/// when asked, the Jacobian of that gradient (11 × 11 by columns).
struct StencilResults {
  std::vector<double> energy, gradient, jacobian;
};

/// Which instruction set computes the stencils (tests run each where the CPU has it).
enum class StencilPath { kWidest, kAvx2, kPortable };

void BendTwistStencils(const StencilColumns& in, int count, bool with_jacobian,
                       StencilResults* out, StencilPath path = StencilPath::kWidest);

}  // namespace stokesrods
