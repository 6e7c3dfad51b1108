// BendTwistStencils' loop over batches of W stencils in the lanes of V (a GCC vector of W
// doubles, or double with W = 1), for the translation units of each instruction set
// (stencil_batch*.cc): internal linkage, as stencil_lanes.h, and nothing from the standard
// library (stencil_columns.h).
#pragma once

#include "stokesrods/elastic/stencil_columns.h"
#include "stokesrods/elastic/stencil_lanes.h"

namespace stokesrods {
namespace {

// W consecutive values of a column from `first` into the lanes; past `lanes` the last one again
// (the spare lanes compute a valid stencil whose results are dropped).
template <class V, int W>
V LoadLanes(const double* column, int first, int lanes) {
  double values[W];
  for (int k = 0; k < W; ++k) values[k] = column[first + (k < lanes ? k : lanes - 1)];
  V v;
  __builtin_memcpy(&v, values, sizeof(V));
  return v;
}

template <class V, int W>
L3<V> LoadLanes3(const double* const* columns, int first, int lanes) {
  return {LoadLanes<V, W>(columns[0], first, lanes), LoadLanes<V, W>(columns[1], first, lanes),
          LoadLanes<V, W>(columns[2], first, lanes)};
}

// The outputs as BendTwistStencilsAvx512's (stencil_columns.h), sized by the caller.
template <class V, int W>
void StencilBatches(const StencilColumns& in, int count, bool with_jacobian, double* energy_out,
                    double* gradient_out, double* jacobian_out) {
  static_assert(sizeof(V) == W * sizeof(double));
  for (int s = 0; s < count; s += W) {
    const int lanes = count - s < W ? count - s : W;
    StencilIn<V> lane_in;
    lane_in.e0 = LoadLanes3<V, W>(in.edge, s, lanes);
    lane_in.e1 = LoadLanes3<V, W>(in.edge, s + 1, lanes);
    lane_in.l0 = LoadLanes<V, W>(in.length, s, lanes);
    lane_in.l1 = LoadLanes<V, W>(in.length, s + 1, lanes);
    lane_in.m1a = LoadLanes3<V, W>(in.m1, s, lanes);
    lane_in.m2a = LoadLanes3<V, W>(in.m2, s, lanes);
    lane_in.m1b = LoadLanes3<V, W>(in.m1, s + 1, lanes);
    lane_in.m2b = LoadLanes3<V, W>(in.m2, s + 1, lanes);
    lane_in.kb = LoadLanes3<V, W>(in.curvature_binormal, s, lanes);
    lane_in.d = LoadLanes<V, W>(in.denominator, s, lanes);
    lane_in.excess1 = LoadLanes<V, W>(in.excess[0], s, lanes);
    lane_in.excess2 = LoadLanes<V, W>(in.excess[1], s, lanes);
    lane_in.bend = LoadLanes<V, W>(in.bend, s, lanes);
    lane_in.twist_stiffness = LoadLanes<V, W>(in.twist_stiffness, s, lanes);
    lane_in.twist = LoadLanes<V, W>(in.twist, s, lanes);
    V energy, gradient[11], jacobian[121];
    if (with_jacobian)
      BendTwistStencil<true>(lane_in, &energy, gradient, jacobian);
    else
      BendTwistStencil<false>(lane_in, &energy, gradient, jacobian);
    // The lanes out by stencil (V[i] holds stencil k's value i in lane k).
    double e[W], g[11 * W], j[121 * W];
    __builtin_memcpy(e, &energy, sizeof(energy));
    __builtin_memcpy(g, gradient, sizeof(gradient));
    if (with_jacobian) __builtin_memcpy(j, jacobian, sizeof(jacobian));
    for (int k = 0; k < lanes; ++k) {
      const int stencil = s + k;
      energy_out[stencil] = e[k];
      for (int i = 0; i < 11; ++i) gradient_out[11 * stencil + i] = g[W * i + k];
      if (with_jacobian)
        for (int i = 0; i < 121; ++i) jacobian_out[121 * stencil + i] = j[W * i + k];
    }
  }
}

// MaterialFrames' loop over batches of W edges (Math: the instruction set's Sin(V), Cos(V)).
template <class V, int W, class Math>
void MaterialFrameBatches(const MaterialFrameColumns& c, int count) {
  static_assert(sizeof(V) == W * sizeof(double));
  for (int j = 0; j < count; j += W) {
    const int lanes = count - j < W ? count - j : W;
    const V theta = LoadLanes<V, W>(c.theta, j, lanes);
    const V cos = Math::Cos(theta), sin = Math::Sin(theta);
    for (int k = 0; k < 3; ++k) {
      const V d1 = LoadLanes<V, W>(c.d1[k], j, lanes), d2 = LoadLanes<V, W>(c.d2[k], j, lanes);
      const V m1 = cos * d1 + sin * d2, m2 = cos * d2 - sin * d1;
      double out1[W], out2[W];
      __builtin_memcpy(out1, &m1, sizeof(V));
      __builtin_memcpy(out2, &m2, sizeof(V));
      for (int l = 0; l < lanes; ++l) c.m1[k][j + l] = out1[l], c.m2[k][j + l] = out2[l];
    }
  }
}

}  // namespace
}  // namespace stokesrods
