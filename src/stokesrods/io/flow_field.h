// The fluid velocity on a plane grid (paper Fig. 6b), written for ParaView and NumPy.
#pragma once

#include <string>

#include "stokesrods/io/config.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {

/// Solves U = 𝕄 F for the nodal forces at the state's positions and velocities (no-slip at every
/// node at this instant) and evaluates the fluid velocity (eq. 9 for RSS) at the grid points
/// origin + i/(n_u − 1) u + j/(n_v − 1) v. Writes flow/flow_NNNNN.vts (a StructuredGrid with the
/// point vector "velocity") and flow/flow_NNNNN.csv (x, y, z, ux, uy, uz), and returns the .vts
/// path relative to output_dir.
std::string WriteFlowField(const Model& model, const State& state, const FlowFieldConfig& plane,
                           const std::string& output_dir, int index);

}  // namespace stokesrods
