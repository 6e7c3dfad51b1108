// A rod's frame transport by columns and the entry points of the instruction-set files
// (frames_avx512.cc, frames_avx2.cc). Free of Eigen and the standard library, as
// elastic/stencil_columns.h (the test IsaObjectsShareNoInlineCode checks). Internal to the rod
// module: the rest of the code calls TransportFramesAndTwists (rod/frames.h).
#pragma once

namespace stokesrods {

/// One rod of `edges` edges by columns (x, y, z each). In: the node positions (edges + 1
/// entries), the old tangents and d1 of each edge. Out: the new tangents, d1, d2 of each edge
/// and, per interior node i (1 … edges − 1, at index i − 1), the signed angle about t^i from the
/// parallel transport of d1^{i−1} to d1^i. Out also, for the caller's checks: the smallest edge
/// length, the smallest 1 + t₀ · t₁ over all transports and the smallest norm of a projected d1
/// (`smallest` 0, 1, 2; a lane that is not a number passes them: the caller checks the angles).
struct FrameColumns {
  const double* x[3] = {};
  const double* old_tangent[3] = {};
  const double* old_d1[3] = {};
  double* tangent[3] = {};
  double* d1[3] = {};
  double* d2[3] = {};
  double* angle = nullptr;
  double smallest[3] = {};
};

/// Call only where the CPU has the instruction set.
void TransportFrameLanesAvx512(int edges, FrameColumns* columns);
void TransportFrameLanesAvx2(int edges, FrameColumns* columns);

}  // namespace stokesrods
