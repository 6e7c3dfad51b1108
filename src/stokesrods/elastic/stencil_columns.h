// The stencils' inputs by columns and the entry points of the instruction-set files
// (stencil_batch_avx512.cc, stencil_batch_avx2.cc). Free of Eigen and the standard library: those
// files include nothing else, so that no inline function of a shared header is compiled there
// with instructions that the CPU running the program may lack (the linker keeps one copy of each
// inline function, whichever file it comes from; the test IsaObjectsShareNoInlineCode checks).
// Internal to the elastic module: the rest of the code calls BendTwistStencils
// (stencil_batch.h).
#pragma once

namespace stokesrods {

/// The inputs of `count` stencils by columns. Stencil s sits between edges s and s + 1: the edge
/// columns hold count + 1 entries, the stencil columns count.
struct StencilColumns {
  const double* edge[3] = {};      ///< edge vectors e = x_{j+1} − x_j
  const double* length = nullptr;  ///< |e|
  const double* m1[3] = {};        ///< material directors m1, m2 of the edges
  const double* m2[3] = {};
  const double* curvature_binormal[3] = {};  ///< κb = 2 e0 × e1 / D of the stencil
  const double* denominator = nullptr;       ///< D = |e0||e1| + e0·e1
  const double* excess[2] = {};              ///< κ⁽¹⁾ − κ̄⁽¹⁾, κ⁽²⁾ − κ̄⁽²⁾
  const double* bend = nullptr;              ///< EI / Δl of the stencil's node
  const double* twist_stiffness = nullptr;   ///< GJ / Δl
  const double* twist = nullptr;             ///< τ − τ̄
};

/// The material directors of edges by columns: m1 = cos θ d1 + sin θ d2, m2 = −sin θ d1 + cos θ d2
/// (rod/frames.h MaterialFrame).
struct MaterialFrameColumns {
  const double* theta = nullptr;  ///< twist angle θ of each edge
  const double* d1[3] = {};       ///< reference directors
  const double* d2[3] = {};
  double* m1[3] = {};             ///< out
  double* m2[3] = {};
};

/// Per stencil s: energy[s], gradient[11 s … 11 s + 10] (stencil DOFs) and, with_jacobian,
/// jacobian[121 s …] (11 × 11 by columns). Call only where the CPU has the instruction set.
void BendTwistStencilsAvx512(const StencilColumns& in, int count, bool with_jacobian,
                             double* energy, double* gradient, double* jacobian);
void BendTwistStencilsAvx2(const StencilColumns& in, int count, bool with_jacobian,
                           double* energy, double* gradient, double* jacobian);
/// The material directors of `count` edges; the sine and cosine by glibc's vector math library
/// (libmvec). Call only where the CPU has the instruction set.
void MaterialFramesAvx512(const MaterialFrameColumns& frames, int count);
void MaterialFramesAvx2(const MaterialFrameColumns& frames, int count);

}  // namespace stokesrods
