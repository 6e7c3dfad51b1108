// Assembly of the elastic forces of a rod: one loop over the stencils scatters the kernel results
// of elastic/ through the DOF map (paper eq. 6: F_int = −∂(E_s + E_b + E_t)/∂q).
#pragma once

#include "stokesrods/elastic/stencil_batch.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"
#include "stokesrods/solver/banded_matrix.h"

namespace stokesrods {

/// Elastic energy [J] of `rod` at the global DOF vector q, with `frames` transported to q.
/// Adds −∂E/∂q into the rod's entries of the global `force` and ∂²E/∂q² into `hessian` (the rod's
/// banded matrix, local indices) when they are not null.
/// Computed by edges (each edge's terms once for its two stencils; sim/elastic_assembly.cc), the
/// stencils' bending and twisting on the widest instruction set the CPU has, or on `path` (tests).
double AddElasticForces(const RodModel& rod, const VecX& q, const RodFrames& frames, VecX* force,
                        BandedMatrix* hessian, StencilPath path = StencilPath::kWidest);

/// The same stencil by stencil, each by the energies of elastic/ (which tests/elastic/ checks
/// against finite differences): the reference AddElasticForces is tested against.
double AddElasticForcesPerStencil(const RodModel& rod, const VecX& q, const RodFrames& frames,
                                  VecX* force, BandedMatrix* hessian);

}  // namespace stokesrods
