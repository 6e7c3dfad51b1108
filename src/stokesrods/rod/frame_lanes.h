// The time-parallel transport of a rod's reference frames and its reference twists, several
// edges per vector (the arithmetic of rod/frames.cc's ParallelTransport, OrthonormalFrame,
// EdgeTangents and ReferenceTwist, in another order of rounding), for the translation units of
// each instruction set (frames_avx512.cc, frames_avx2.cc): internal linkage, as
// elastic/stencil_lanes.h, and nothing from the standard library or Eigen (an instruction set's
// copy of a template another unit also instantiates could be the one the linker keeps).
//
// V is a GCC vector of W doubles; Math has the instruction set's Sqrt(V) and Atan2(y, x) (the
// arctangent from glibc's vector math library, libmvec). The columns are the caller's
// (frames.cc, TransportFramesAndTwists).
#pragma once

#include "stokesrods/rod/frame_columns.h"

namespace stokesrods {
namespace {

template <class V>
struct FrameL3 {
  V x, y, z;
};

template <class V>
inline V Dot(const FrameL3<V>& a, const FrameL3<V>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

template <class V>
inline FrameL3<V> Cross(const FrameL3<V>& a, const FrameL3<V>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

template <class V>
inline FrameL3<V> Scaled(V s, const FrameL3<V>& a) {
  return {s * a.x, s * a.y, s * a.z};
}

// R u = c u + b × u + (b · u) b / (1 + c), b = t0 × t1, c = t0 · t1 (frames.cc ParallelTransport).
// *one_plus_c: 1 + c, for the caller's check.
template <class V>
inline FrameL3<V> Transport(const FrameL3<V>& u, const FrameL3<V>& t0, const FrameL3<V>& t1,
                            V* one_plus_c) {
  const FrameL3<V> b = Cross(t0, t1);
  const V c = Dot(t0, t1);
  *one_plus_c = 1.0 + c;
  const FrameL3<V> bu = Cross(b, u);
  const V k = Dot(b, u) / *one_plus_c;
  return {c * u.x + bu.x + k * b.x, c * u.y + bu.y + k * b.y, c * u.z + bu.z + k * b.z};
}

// W consecutive values from `first`; past `lanes` the last one again (the spare lanes compute a
// valid edge whose results are dropped).
template <class V, int W>
inline V LoadColumn(const double* column, int first, int lanes) {
  V v;
  if (lanes == W) {
    __builtin_memcpy(&v, column + first, sizeof(V));
    return v;
  }
  double values[W];
  for (int k = 0; k < W; ++k) values[k] = column[first + (k < lanes ? k : lanes - 1)];
  __builtin_memcpy(&v, values, sizeof(V));
  return v;
}

template <class V, int W>
inline FrameL3<V> LoadColumns(const double* const* columns, int first, int lanes) {
  return {LoadColumn<V, W>(columns[0], first, lanes), LoadColumn<V, W>(columns[1], first, lanes),
          LoadColumn<V, W>(columns[2], first, lanes)};
}

template <class V, int W>
inline void StoreColumn(V v, int first, int lanes, double* column) {
  if (lanes == W) {
    __builtin_memcpy(column + first, &v, sizeof(V));
    return;
  }
  double values[W];
  __builtin_memcpy(values, &v, sizeof(V));
  for (int k = 0; k < lanes; ++k) column[first + k] = values[k];
}

template <class V, int W>
inline void StoreColumns(const FrameL3<V>& v, int first, int lanes, double* const* columns) {
  StoreColumn<V, W>(v.x, first, lanes, columns[0]);
  StoreColumn<V, W>(v.y, first, lanes, columns[1]);
  StoreColumn<V, W>(v.z, first, lanes, columns[2]);
}

template <class V, int W>
inline double SmallestLane(V v) {
  double values[W];
  __builtin_memcpy(values, &v, sizeof(V));
  double smallest = values[0];
  for (int k = 1; k < W; ++k) smallest = values[k] < smallest ? values[k] : smallest;
  return smallest;
}

template <class V, int W, class Math>
void TransportFrameLanes(int edges, FrameColumns* c) {
  static_assert(sizeof(V) == W * sizeof(double));
  V smallest_length = V{} + 1e300, smallest_c = V{} + 1e300, smallest_norm = V{} + 1e300;
  for (int j = 0; j < edges; j += W) {
    const int lanes = edges - j < W ? edges - j : W;
    const FrameL3<V> a = LoadColumns<V, W>(c->x, j, lanes);
    const FrameL3<V> b = LoadColumns<V, W>(c->x, j + 1, lanes);
    const FrameL3<V> e = {b.x - a.x, b.y - a.y, b.z - a.z};
    const V length = Math::Sqrt(Dot(e, e));
    const FrameL3<V> t = {e.x / length, e.y / length, e.z / length};
    V one_plus_c;
    const FrameL3<V> u = Transport(LoadColumns<V, W>(c->old_d1, j, lanes),
                                   LoadColumns<V, W>(c->old_tangent, j, lanes), t, &one_plus_c);
    const V ut = Dot(u, t);
    const FrameL3<V> p = {u.x - ut * t.x, u.y - ut * t.y, u.z - ut * t.z};
    const V norm = Math::Sqrt(Dot(p, p));
    const FrameL3<V> d1 = {p.x / norm, p.y / norm, p.z / norm};
    StoreColumns<V, W>(t, j, lanes, c->tangent);
    StoreColumns<V, W>(d1, j, lanes, c->d1);
    StoreColumns<V, W>(Cross(t, d1), j, lanes, c->d2);
    smallest_length = length < smallest_length ? length : smallest_length;
    smallest_c = one_plus_c < smallest_c ? one_plus_c : smallest_c;
    smallest_norm = norm < smallest_norm ? norm : smallest_norm;
  }
  for (int i = 1; i + 1 <= edges; i += W) {  // interior node i: edges i − 1 and i
    const int lanes = edges - i < W ? edges - i : W;
    const FrameL3<V> t1 = LoadColumns<V, W>(c->tangent, i, lanes);
    const FrameL3<V> d1 = LoadColumns<V, W>(c->d1, i, lanes);
    V one_plus_c;
    const FrameL3<V> v = Transport(LoadColumns<V, W>(c->d1, i - 1, lanes),
                                   LoadColumns<V, W>(c->tangent, i - 1, lanes), t1, &one_plus_c);
    StoreColumn<V, W>(Math::Atan2(Dot(Cross(v, d1), t1), Dot(v, d1)), i - 1, lanes, c->angle);
    smallest_c = one_plus_c < smallest_c ? one_plus_c : smallest_c;
  }
  c->smallest[0] = SmallestLane<V, W>(smallest_length);
  c->smallest[1] = SmallestLane<V, W>(smallest_c);
  c->smallest[2] = SmallestLane<V, W>(smallest_norm);
}

}  // namespace
}  // namespace stokesrods
