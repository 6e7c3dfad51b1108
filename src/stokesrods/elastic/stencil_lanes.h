// The bending and twisting of a node's stencil (energy, gradient and its Jacobian in the 11
// stencil DOFs) written once over a lane type T: double, or a vector of doubles (GCC's vector
// extension; clang has it too) that computes W stencils at once, one per lane. Included only by
// stencil_batch*.cc, each compiled for one instruction set, so everything here has internal
// linkage (no instance compiled for one set can be picked by the linker for another).
//
// The formulas are those of the rod's assembly by edges (sim/elastic_assembly.cc) and of
// BendingEdgeEnergy / TwistingEdgeEnergy (elastic/bending.cc, twisting.cc), in components. In the
// edge variables y = (e0, θ0, e1, θ1) (curvature.h), with κb = 2 n / D, n = e0 × e1,
// D = l0 l1 + e0·e1, the material curvatures κ⁽¹⁾ = ½ m2·κb, κ⁽²⁾ = −½ m1·κb (m = m⁰ + m¹), the
// excess Δκ = κ − κ̄, k = EI/Δl, k_t = GJ/Δl and the twist excess Δτ:
//   E = ½ k |Δκ|² + ½ k_t Δτ²,
//   ∂E/∂e = (∂κb/∂e)ᵀ w + ½ k_t Δτ κb / l_j (on e_j),  w = ½ k (Δκ⁽¹⁾ m2 − Δκ⁽²⁾ m1),
//   ∂E/∂θ_j = −½ k (Δκ⁽¹⁾ m1ʲ·κb + Δκ⁽²⁾ m2ʲ·κb) ∓ k_t Δτ,
// (∂κb/∂e)ᵀ w = ((2/D) e1 × w − (κb·w/D) ∇_e0 D, (2/D) w × e0 − (κb·w/D) ∇_e1 D),
// ∇_e0 D = l1 t0 + e1, ∇_e1 D = l0 t1 + e0. The Jacobian of that gradient, with the frames
// transported in time (bending.h: not symmetric), gathered into one 8 × 8 matrix:
//   k Σ_a ∇κ_a ∇κ_aᵀ + k_t ∇τ ∇τᵀ                                   (the rank-3 part)
//   + ½ ∇²(w'·κb) − Σ_j (½/l_j) (∂κb/∂e)ᵀ t_j u_jᵀ   (columns of e_j)  (bending, edges)
//   + k_t Δτ [∂κb/∂e_j / (2 l_j) − δ_ij κb t_jᵀ / (2 l_j²)]           (twisting, edges)
//   −½ u_j·κb on (θ_j, θ_j), ½ (∂κb/∂e)ᵀ u'_j on (e, θ_j) and (θ_j, e),
// u_j = k (Δκ⁽¹⁾ m2ʲ − Δκ⁽²⁾ m1ʲ), u'_j = −k (Δκ⁽¹⁾ m1ʲ + Δκ⁽²⁾ m2ʲ), w' = u_0 + u_1, and
//   ∇²(w'·κb) = 2∇²f/D − 2(∇f ∇Dᵀ + ∇D ∇fᵀ)/D² + 4 f ∇D ∇Dᵀ/D³ − 2 f ∇²D/D²,
// f = w'·n, ∇f = (e1 × w', w' × e0), ∇²f = [[0, −[w']×], [[w']×, 0]],
// ∇²D = [[(l1/l0) P0, I + t0 t1ᵀ], [I + t1 t0ᵀ, (l0/l1) P1]], P = I − t tᵀ
// (CalcCurvatureBinormalHessian). Finally the map to the stencil DOFs, Mᵀ g and Mᵀ H M, by the
// ±1 pattern of M (EdgeToStencilGradient, EdgeToStencilHessian). Checked against the stencil-by-
// stencil reference on every path (tests/sim/jacobian_test.cc, ElasticAssembly.*).
#pragma once

namespace stokesrods {
namespace {

/// A 3-vector of lanes.
template <class T>
struct L3 {
  T x, y, z;
};
template <class T>
L3<T> operator+(const L3<T>& a, const L3<T>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
L3<T> operator-(const L3<T>& a, const L3<T>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
L3<T> operator*(const T& s, const L3<T>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <class T>
T Dot(const L3<T>& a, const L3<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
L3<T> Cross(const L3<T>& a, const L3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
T At(const L3<T>& a, int i) {
  return i == 0 ? a.x : (i == 1 ? a.y : a.z);
}

/// The inputs of a stencil (node i between edges i − 1 and i), per lane.
template <class T>
struct StencilIn {
  L3<T> e0, e1;              // the edges
  T l0, l1;                  // their lengths
  L3<T> m1a, m2a, m1b, m2b;  // their material directors (edge i − 1: a, edge i: b)
  L3<T> kb;                  // the curvature binormal κb
  T d;                       // its denominator D
  T excess1, excess2;        // Δκ = κ − κ̄
  T bend;                    // EI / Δl_i
  T twist_stiffness;         // GJ / Δl_i
  T twist;                   // Δτ = τ − τ̄
};

/// Energy, gradient (11, stencil DOFs) and, with kJacobian, the Jacobian of the gradient (11 × 11
/// by columns) of the stencils in the lanes of `s`. κb, D and Δκ come in computed as the rest
/// curvature was (MaterialCurvatures, scalar and without fused multiply–adds), so that a rod at
/// rest has a bending force of exactly zero on every instruction set.
template <bool kJacobian, class T>
void BendTwistStencil(const StencilIn<T>& s, T* energy, T* gradient, T* jacobian) {
  const L3<T>& kb = s.kb;
  const T inv_d = 1.0 / s.d;
  const L3<T> m1 = s.m1a + s.m1b, m2 = s.m2a + s.m2b;
  const T ex0 = s.excess1, ex1 = s.excess2;
  *energy = 0.5 * s.bend * (ex0 * ex0 + ex1 * ex1) + 0.5 * s.twist_stiffness * s.twist * s.twist;
  const T tm = s.twist_stiffness * s.twist;  // the twisting moment k_t Δτ
  const T inv_l0 = 1.0 / s.l0, inv_l1 = 1.0 / s.l1;
  const L3<T> w = (0.5 * s.bend) * (ex0 * m2 - ex1 * m1);
  const T kb_w = Dot(kb, w) * inv_d;
  const T two_inv_d = 2.0 * inv_d;
  const L3<T> ge0 = two_inv_d * Cross(s.e1, w) - kb_w * ((s.l1 * inv_l0) * s.e0 + s.e1) +
                    (0.5 * tm * inv_l0) * kb;
  const L3<T> ge1 = two_inv_d * Cross(w, s.e0) - kb_w * ((s.l0 * inv_l1) * s.e1 + s.e0) +
                    (0.5 * tm * inv_l1) * kb;
  const T gt0 = -0.5 * s.bend * (ex0 * Dot(s.m1a, kb) + ex1 * Dot(s.m2a, kb)) - tm;
  const T gt1 = -0.5 * s.bend * (ex0 * Dot(s.m1b, kb) + ex1 * Dot(s.m2b, kb)) + tm;
  // Mᵀ g: (x0, θ0, x1, θ1, x2) ← (−e0, θ0, e0 − e1, θ1, e1).
  const L3<T> gx1 = ge0 - ge1;
  gradient[0] = -ge0.x, gradient[1] = -ge0.y, gradient[2] = -ge0.z;
  gradient[3] = gt0;
  gradient[4] = gx1.x, gradient[5] = gx1.y, gradient[6] = gx1.z;
  gradient[7] = gt1;
  gradient[8] = ge1.x, gradient[9] = ge1.y, gradient[10] = ge1.z;
  if constexpr (!kJacobian) return;

  const L3<T> t0 = inv_l0 * s.e0, t1 = inv_l1 * s.e1;
  const L3<T> dg0 = s.l1 * t0 + s.e1, dg1 = s.l0 * t1 + s.e0;  // ∇D
  const T dg[6] = {dg0.x, dg0.y, dg0.z, dg1.x, dg1.y, dg1.z};
  // J = ∂κb/∂(e0, e1) by columns: (2 ∂n/∂e_c − κb ∂D/∂e_c) / D, ∂n/∂e0 = −[e1]×, ∂n/∂e1 = [e0]×.
  L3<T> jc[6];
  {
    const L3<T> u[3] = {{T{}, -s.e1.z, s.e1.y},   // u_x × e1
                        {s.e1.z, T{}, -s.e1.x},   // u_y × e1
                        {-s.e1.y, s.e1.x, T{}}};  // u_z × e1
    const L3<T> v[3] = {{T{}, s.e0.z, -s.e0.y},   // e0 × u_x
                        {-s.e0.z, T{}, s.e0.x},   // e0 × u_y
                        {s.e0.y, -s.e0.x, T{}}};  // e0 × u_z
    for (int c = 0; c < 3; ++c) {
      jc[c] = two_inv_d * u[c] - (inv_d * dg[c]) * kb;
      jc[3 + c] = two_inv_d * v[c] - (inv_d * dg[3 + c]) * kb;
    }
  }
  // The gradients of κ⁽¹⁾, κ⁽²⁾ and τ in y (columns of G, 8 × 3).
  T g[3][8];
  for (int c = 0; c < 6; ++c) {
    const int row = c < 3 ? c : c + 1;
    g[0][row] = 0.5 * Dot(jc[c], m2);
    g[1][row] = -0.5 * Dot(jc[c], m1);
  }
  g[0][3] = -0.5 * Dot(s.m1a, kb), g[0][7] = -0.5 * Dot(s.m1b, kb);
  g[1][3] = -0.5 * Dot(s.m2a, kb), g[1][7] = -0.5 * Dot(s.m2b, kb);
  {
    const T half_l0 = 0.5 * inv_l0, half_l1 = 0.5 * inv_l1;
    g[2][0] = half_l0 * kb.x, g[2][1] = half_l0 * kb.y, g[2][2] = half_l0 * kb.z;
    g[2][4] = half_l1 * kb.x, g[2][5] = half_l1 * kb.y, g[2][6] = half_l1 * kb.z;
    g[2][3] = T{} - 1.0, g[2][7] = T{} + 1.0;
  }
  T h[8][8];  // h[i][k] = ∂g_i/∂y_k
  for (int i = 0; i < 8; ++i)
    for (int k = 0; k < 8; ++k)
      h[i][k] = s.bend * (g[0][i] * g[0][k] + g[1][i] * g[1][k]) +
                s.twist_stiffness * (g[2][i] * g[2][k]);
  const L3<T> u0 = s.bend * (ex0 * s.m2a - ex1 * s.m1a);
  const L3<T> u1 = s.bend * (ex0 * s.m2b - ex1 * s.m1b);
  const L3<T> du0 = -s.bend * (ex0 * s.m1a + ex1 * s.m2a);
  const L3<T> du1 = -s.bend * (ex0 * s.m1b + ex1 * s.m2b);
  // The edges' block, ½ ∇²(w'·κb) and the edge terms of bending and twisting (6 × 6).
  T e[6][6];
  {
    const L3<T> wp = u0 + u1;
    const T f = Dot(wp, Cross(s.e0, s.e1));  // w'·n
    const L3<T> gf0 = Cross(s.e1, wp), gf1 = Cross(wp, s.e0);
    const T gf[6] = {gf0.x, gf0.y, gf0.z, gf1.x, gf1.y, gf1.z};
    const T inv_d2 = inv_d * inv_d;
    const T f_d2 = f * inv_d2, two_f_d3 = 2.0 * f_d2 * inv_d;
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c)
        e[r][c] = two_f_d3 * dg[r] * dg[c] - inv_d2 * (gf[r] * dg[c] + dg[r] * gf[c]);
    // inv_d ∇²f/2·2: the off-diagonal blocks −[w']× (top right) and [w']× (bottom left).
    const T wx = inv_d * wp.x, wy = inv_d * wp.y, wz = inv_d * wp.z;
    e[0][4] += wz, e[0][5] -= wy, e[1][3] -= wz, e[1][5] += wx, e[2][3] += wy, e[2][4] -= wx;
    e[3][1] -= wz, e[3][2] += wy, e[4][0] += wz, e[4][2] -= wx, e[5][0] -= wy, e[5][1] += wx;
    // − f/D² ∇²D.
    const T tl = f_d2 * s.l1 * inv_l0, br = f_d2 * s.l0 * inv_l1;
    const T t0v[3] = {t0.x, t0.y, t0.z}, t1v[3] = {t1.x, t1.y, t1.z};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        e[r][c] += tl * (t0v[r] * t0v[c]);
        e[3 + r][3 + c] += br * (t1v[r] * t1v[c]);
        e[r][3 + c] -= f_d2 * (t0v[r] * t1v[c]);
        e[3 + r][c] -= f_d2 * (t1v[r] * t0v[c]);
      }
    for (int r = 0; r < 3; ++r) {
      e[r][r] -= tl, e[3 + r][3 + r] -= br;
      e[r][3 + r] -= f_d2, e[3 + r][r] -= f_d2;
    }
    const L3<T> u[2] = {u0, u1};
    const L3<T> t[2] = {t0, t1};
    const T inv_l[2] = {inv_l0, inv_l1};
    for (int j = 0; j < 2; ++j) {
      const T half_l = 0.5 * inv_l[j], twist_l = 0.5 * tm * inv_l[j];
      const T twist_l2 = twist_l * inv_l[j];
      const T uj[3] = {u[j].x, u[j].y, u[j].z}, tj[3] = {t[j].x, t[j].y, t[j].z};
      for (int r = 0; r < 6; ++r) {
        const T jt_t = half_l * Dot(jc[r], t[j]);  // ½ (Jᵀ t_j)_r / l_j
        for (int c = 0; c < 3; ++c) e[r][3 * j + c] -= jt_t * uj[c];
      }
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 6; ++c) e[3 * j + r][c] += twist_l * At(jc[c], r);
      const T kbv[3] = {kb.x, kb.y, kb.z};
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) e[3 * j + r][3 * j + c] -= twist_l2 * (kbv[r] * tj[c]);
    }
  }
  constexpr int kEdgeRow[2] = {0, 4};
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) h[kEdgeRow[a] + r][kEdgeRow[b] + c] += e[3 * a + r][3 * b + c];
  {
    const L3<T> du[2] = {du0, du1};
    h[3][3] -= 0.5 * Dot(u0, kb);
    h[7][7] -= 0.5 * Dot(u1, kb);
    for (int j = 0; j < 2; ++j) {
      const int th = j == 0 ? 3 : 7;
      for (int c = 0; c < 6; ++c) {
        const T mixed = 0.5 * Dot(jc[c], du[j]);
        const int row = c < 3 ? c : c + 1;
        h[row][th] += mixed;
        h[th][row] += mixed;
      }
    }
  }
  // Mᵀ h M, by columns into jacobian (11 × 11): first a = h M (8 × 11), then Mᵀ a.
  T a[8][11];
  for (int i = 0; i < 8; ++i) {
    for (int c = 0; c < 3; ++c) {
      a[i][c] = -h[i][c];
      a[i][4 + c] = h[i][c] - h[i][4 + c];
      a[i][8 + c] = h[i][4 + c];
    }
    a[i][3] = h[i][3];
    a[i][7] = h[i][7];
  }
  for (int col = 0; col < 11; ++col) {
    T* out = jacobian + 11 * col;
    for (int r = 0; r < 3; ++r) {
      out[r] = -a[r][col];
      out[4 + r] = a[r][col] - a[4 + r][col];
      out[8 + r] = a[4 + r][col];
    }
    out[3] = a[3][col];
    out[7] = a[7][col];
  }
}

}  // namespace
}  // namespace stokesrods
