// The bending and twisting of all the stencils of a rod at once, several stencils per vector
// (elastic/stencil_lanes.h): AVX-512 (eight lanes of doubles) or AVX2 with FMA (four) where the
// CPU has them, else one stencil at a time. The rod's assembly (sim/elastic_assembly.cc) gathers
// the inputs by columns and scatters the results into its force and banded Jacobian.
#pragma once

#include <vector>

#include "stokesrods/elastic/stencil_columns.h"

namespace stokesrods {

/// Per stencil: its energy, its gradient in the stencil DOFs (x0, θ0, x1, θ1, x2) (11 values) and,
/// when asked, the Jacobian of that gradient (11 × 11 by columns).
struct StencilResults {
  std::vector<double> energy, gradient, jacobian;
};

/// Which instruction set computes the stencils (tests run each where the CPU has it).
enum class StencilPath { kWidest, kAvx2, kPortable };

void BendTwistStencils(const StencilColumns& in, int count, bool with_jacobian,
                       StencilResults* out, StencilPath path = StencilPath::kWidest);

/// The material directors of `count` edges (stencil_columns.h), several per vector where the CPU
/// allows (the sine and cosine by glibc's vector math library), else by MaterialFrame.
void MaterialFrames(const MaterialFrameColumns& frames, int count,
                    StencilPath path = StencilPath::kWidest);

}  // namespace stokesrods
