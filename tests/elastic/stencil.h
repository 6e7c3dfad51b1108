// Test helpers for the elastic kernels: a random bending/twisting stencil, its perturbation with
// the reference frames carried by time-parallel transport (as Newton sees the energy), and
// central finite differences of energy and gradient.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <random>

#include "stokesrods/common/types.h"
#include "stokesrods/rod/frames.h"

namespace stokesrods::testing {

/// Nodes, edge frames, twist angles and the reference twist of one interior node.
struct Stencil {
  Vec3 x[3];
  RefFrame f[2];
  double theta[2] = {0.0, 0.0};
  double reference_twist = 0.0;  ///< m_ref [rad]
};

inline Vec3 Tangent(const Stencil& s, int edge) { return (s.x[edge + 1] - s.x[edge]).normalized(); }

inline double CalcReferenceTwist(const Stencil& s, double previous) {
  return ReferenceTwist(s.f[0], Tangent(s, 0), s.f[1], Tangent(s, 1), previous);
}

/// Local DOFs q = (x0, θ0, x1, θ1, x2).
inline Vec11 Pack(const Stencil& s) {
  Vec11 q;
  q << s.x[0], s.theta[0], s.x[1], s.theta[1], s.x[2];
  return q;
}

/// The stencil at DOFs q: frames transported in time from the tangents of `base` to the new
/// tangents, reference twist recomputed on the branch closest to that of `base`.
inline Stencil Perturb(const Stencil& base, const Vec11& q) {
  Stencil s;
  s.x[0] = q.segment<3>(0);
  s.x[1] = q.segment<3>(4);
  s.x[2] = q.segment<3>(8);
  s.theta[0] = q[3];
  s.theta[1] = q[7];
  for (int j = 0; j < 2; ++j) {
    const Vec3 t_old = Tangent(base, j);
    const Vec3 t_new = Tangent(s, j);
    s.f[j].d1 = ParallelTransport(base.f[j].d1, t_old, t_new);
    s.f[j].d2 = ParallelTransport(base.f[j].d2, t_old, t_new);
  }
  s.reference_twist = CalcReferenceTwist(s, base.reference_twist);
  return s;
}

/// A curved, twisted stencil of edge lengths ~ `scale` [m]: turning angle up to ~115°, random
/// reference frames about each tangent, random twist angles, reference twist on a random branch.
inline Stencil RandomStencil(std::mt19937& rng, double scale) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  auto random_unit = [&] { return Vec3(normal(rng), normal(rng), normal(rng)).normalized(); };
  Stencil s;
  const Vec3 t0 = random_unit();
  Vec3 t1 = random_unit();
  while (t0.dot(t1) < -0.4) t1 = random_unit();
  s.x[0] = scale * Vec3(uniform(rng), uniform(rng), uniform(rng));
  s.x[1] = s.x[0] + scale * (1.0 + 0.5 * uniform(rng)) * t0;
  s.x[2] = s.x[1] + scale * (1.0 + 0.5 * uniform(rng)) * t1;
  const Vec3 t[2] = {t0, t1};
  for (int j = 0; j < 2; ++j) {
    const Vec3 d1 = random_unit();
    s.f[j].d1 = (d1 - d1.dot(t[j]) * t[j]).normalized();
    s.f[j].d2 = t[j].cross(s.f[j].d1);
    s.theta[j] = 3.0 * uniform(rng);
  }
  s.reference_twist = CalcReferenceTwist(s, 2.0 * kPi * std::round(2.0 * uniform(rng)));
  return s;
}

/// Energy of a stencil with optional gradient and Hessian in q (x0, θ0, x1, θ1, x2).
using StencilEnergy = std::function<double(const Stencil&, Vec11*, Mat11*)>;

/// Relative error ‖a − b‖ / ‖b‖ (Frobenius for matrices).
template <typename A, typename B>
double RelativeError(const A& a, const B& b) {
  return (a - b).norm() / b.norm();
}

/// Diagonal scaling D = diag(L, L, L, 1, L, L, L, 1, L, L, L): in the dimensionless DOFs
/// (x/L, θ) the gradient is D g and the Hessian D H D, so positions and angles weigh alike.
inline Vec11 DofScale(double length) {
  Vec11 d = Vec11::Constant(length);
  d[3] = 1.0;
  d[7] = 1.0;
  return d;
}

struct FiniteDifferenceResult {
  double gradient_error;  ///< relative, in dimensionless DOFs
  double hessian_error;   ///< relative, in dimensionless DOFs
};

/// Central differences (step h in the dimensionless DOFs) of E for the gradient and of the
/// analytic gradient for the Hessian, each evaluated at the transported perturbed stencil.
inline FiniteDifferenceResult CheckByFiniteDifferences(const StencilEnergy& energy,
                                                       const Stencil& s, double length,
                                                       double h = 1e-5) {
  const Vec11 q = Pack(s);
  const Vec11 d = DofScale(length);
  Vec11 g;
  Mat11 hess;
  energy(s, &g, &hess);
  Vec11 g_fd;
  Mat11 h_fd;
  for (int k = 0; k < 11; ++k) {
    Vec11 dq = Vec11::Zero();
    dq[k] = h * d[k];
    Vec11 g_plus;
    Vec11 g_minus;
    const double e_plus = energy(Perturb(s, q + dq), &g_plus, nullptr);
    const double e_minus = energy(Perturb(s, q - dq), &g_minus, nullptr);
    g_fd[k] = (e_plus - e_minus) / (2.0 * h);                         // already × d[k]
    h_fd.col(k) = d.asDiagonal() * (g_plus - g_minus) / (2.0 * h);  // D H D, column k
  }
  const Vec11 g_scaled = d.asDiagonal() * g;
  const Mat11 h_scaled = d.asDiagonal() * hess * d.asDiagonal();
  return {RelativeError(g_fd, g_scaled), RelativeError(h_fd, h_scaled)};
}

/// Second differences of E alone (frames transported from `s`, step h in the dimensionless DOFs):
/// the true Hessian of the energy as a function of q, which is symmetric. Returns its relative
/// error against the symmetric part of the analytic gradient Jacobian.
inline double CheckSymmetricPartBySecondDifferences(const StencilEnergy& energy, const Stencil& s,
                                                    double length, double h = 1e-4) {
  const Vec11 q = Pack(s);
  const Vec11 d = DofScale(length);
  Mat11 jac;
  energy(s, nullptr, &jac);
  auto e = [&](const Vec11& dq) { return energy(Perturb(s, q + dq), nullptr, nullptr); };
  Mat11 h_fd;
  for (int k = 0; k < 11; ++k) {
    for (int l = 0; l <= k; ++l) {
      Vec11 a = Vec11::Zero();
      Vec11 b = Vec11::Zero();
      a[k] = h * d[k];
      b[l] = h * d[l];
      h_fd(k, l) = (e(a + b) - e(a - b) - e(b - a) + e(-a - b)) / (4.0 * h * h);
      h_fd(l, k) = h_fd(k, l);
    }
  }
  const Mat11 scaled = d.asDiagonal() * jac * d.asDiagonal();
  return RelativeError(h_fd, Mat11(0.5 * (scaled + scaled.transpose())));
}

/// Rigid motion x → R x + c of the stencil, frames rotated along.
inline Stencil RigidlyMoved(const Stencil& s, const Mat3& rotation, const Vec3& shift) {
  Stencil m = s;
  for (int i = 0; i < 3; ++i) m.x[i] = rotation * s.x[i] + shift;
  for (int j = 0; j < 2; ++j) {
    m.f[j].d1 = rotation * s.f[j].d1;
    m.f[j].d2 = rotation * s.f[j].d2;
  }
  m.reference_twist = CalcReferenceTwist(m, s.reference_twist);
  return m;
}

}  // namespace stokesrods::testing
