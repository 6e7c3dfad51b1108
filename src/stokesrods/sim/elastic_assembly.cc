#include "stokesrods/sim/elastic_assembly.h"

#include <vector>

#include "stokesrods/common/assert.h"
#include "stokesrods/elastic/bending.h"
#include "stokesrods/elastic/stretching.h"
#include "stokesrods/elastic/twisting.h"

namespace stokesrods {

namespace {

// The stretching Hessian of an edge (DOFs a … a + 2 and b … b + 2) into the rod's matrix.
void AddStretchingBlocks(int a, int b, const Mat6& h6, BandedMatrix* hessian) {
  hessian->AddBlock(a, h6.topLeftCorner<3, 3>());
  hessian->AddBlock(b, h6.bottomRightCorner<3, 3>());
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      (*hessian)(a + r, b + c) += h6(r, 3 + c);
      (*hessian)(b + r, a + c) += h6(3 + r, c);
    }
}

// What the stencils of both its nodes share about an edge.
struct EdgeTerms {
  Vec3 e;         // x_{j+1} − x_j
  double length;  // |e|
  Vec3 m1, m2;    // material directors
};

// The Jacobian of the stencil's bending and twisting gradient in y = (e0, θ0, e1, θ1) (edges a,
// b; k = bend, Δκ = excess, k_t = twist_stiffness, k_t Δτ = twist_moment), the formulas of
// BendingEdgeEnergy and TwistingEdgeEnergy gathered into one 8 × 8 matrix:
//   k Σ_a ∇κ_a ∇κ_aᵀ + k_t ∇τ ∇τᵀ                                   (the rank-3 part)
//   + ½ ∇²(w·κb) − Σ_j (½/l_j) (∂κb/∂e)ᵀ t_j u_jᵀ   (columns of e_j)   (bending, edges)
//   + k_t Δτ [∂κb/∂e_j / (2 l_i) − δ_ij κb t_iᵀ / (2 l_i²)]            (twisting, edges)
//   −½ u_j·κb on (θ_j, θ_j), ½ (∂κb/∂e)ᵀ u'_j on (e, θ_j) and (θ_j, e),
// u_j = k (Δκ⁽¹⁾ m2^j − Δκ⁽²⁾ m1^j), u'_j = −k (Δκ⁽¹⁾ m1^j + Δκ⁽²⁾ m2^j), w = u_0 + u_1.
Mat8 StencilJacobian(const EdgeTerms& a, const EdgeTerms& b, double bend, const Vec2& excess,
                     double twist_stiffness, double twist_moment) {
  const StencilCurvature c = CalcStencilCurvature(a.e, b.e, true);
  const Eigen::Matrix<double, 6, 3> jt = c.jacobian.transpose();
  // The gradients of κ⁽¹⁾, κ⁽²⁾ and τ, and u_j, u'_j.
  const Vec6 grad_e[2] = {0.5 * jt * (a.m2 + b.m2), -0.5 * jt * (a.m1 + b.m1)};
  Eigen::Matrix<double, 8, 3> g;
  g.col(0) << grad_e[0].head<3>(), -0.5 * a.m1.dot(c.kb), grad_e[0].tail<3>(),
      -0.5 * b.m1.dot(c.kb);
  g.col(1) << grad_e[1].head<3>(), -0.5 * a.m2.dot(c.kb), grad_e[1].tail<3>(),
      -0.5 * b.m2.dot(c.kb);
  g.col(2) << c.kb / (2.0 * a.length), -1.0, c.kb / (2.0 * b.length), 1.0;
  const EdgeTerms* edge[2] = {&a, &b};
  Vec3 u[2], du[2];
  for (int j = 0; j < 2; ++j) {
    u[j] = bend * (excess[0] * edge[j]->m2 - excess[1] * edge[j]->m1);
    du[j] = -bend * (excess[0] * edge[j]->m1 + excess[1] * edge[j]->m2);
  }
  Mat8 h;
  h.noalias() = g * Vec3(bend, bend, twist_stiffness).asDiagonal() * g.transpose();
  Mat6 edges = 0.5 * CalcCurvatureBinormalHessian(c, u[0] + u[1]);
  for (int j = 0; j < 2; ++j) {
    edges.middleCols<3>(3 * j).noalias() -=
        (0.5 / c.length[j]) * (jt * c.tangent[j]) * u[j].transpose();
    edges.middleRows<3>(3 * j) += (0.5 * twist_moment / c.length[j]) * c.jacobian;
    edges.block<3, 3>(3 * j, 3 * j).noalias() -=
        (0.5 * twist_moment / (c.length[j] * c.length[j])) * c.kb * c.tangent[j].transpose();
  }
  const int edge_index[2] = {kEdge0, kEdge1};
  const int theta_index[2] = {kTheta0, kTheta1};
  for (int i = 0; i < 2; ++i)
    for (int k = 0; k < 2; ++k)
      h.block<3, 3>(edge_index[i], edge_index[k]) += edges.block<3, 3>(3 * i, 3 * k);
  for (int j = 0; j < 2; ++j) {
    const int th = theta_index[j];
    h(th, th) -= 0.5 * u[j].dot(c.kb);
    const Vec6 mixed = 0.5 * jt * du[j];
    for (int i = 0; i < 2; ++i) {
      h.block<3, 1>(edge_index[i], th) += mixed.segment<3>(3 * i);
      h.block<1, 3>(th, edge_index[i]) += mixed.segment<3>(3 * i).transpose();
    }
  }
  return h;
}

// The forces, and the Jacobian where `hessian` is given, by edges: each edge's vector, length and
// material directors are computed once (one sine and one cosine per edge, where the stencils'
// own calls take two per stencil), and the bending gradient in the edges,
// ½ k Σ_a Δκ_a (∂κb/∂e)ᵀ (u_a⁰ + u_a¹) = (∂κb/∂e)ᵀ w, is taken by cross products instead of
// forming ∂κb/∂e (κb = 2 e0 × e1 / D):
//   (∂κb/∂e)ᵀ w = ((2/D) e1 × w − (κb·w/D) ∇_e0 D,  (2/D) w × e0 − (κb·w/D) ∇_e1 D),
//   ∇_e0 D = |e1| t0 + e1, ∇_e1 D = |e0| t1 + e0;
// the Jacobian by StencilJacobian. The arithmetic of StretchingEnergy, BendingEdgeEnergy and
// TwistingEdgeEnergy otherwise; ElasticAssembly.* (tests/sim/jacobian_test.cc) compares it with
// AddElasticForcesPerStencil.
double AddElasticForcesByEdge(const RodModel& rod, const VecX& q, const RodFrames& frames,
                              VecX* force, BandedMatrix* hessian) {
  const int n = rod.num_nodes();
  const int o = rod.dof_offset;
  auto x = [&](int i) { return Vec3(q.segment<3>(o + NodeDof(i))); };
  double energy = 0.0;
  thread_local std::vector<EdgeTerms> edges;  // kept: no allocation per evaluation
  edges.resize(static_cast<size_t>(n - 1));
  Vec6 g6;
  Mat6 h6;
  for (int j = 0; j + 1 < n; ++j) {
    EdgeTerms& edge = edges[static_cast<size_t>(j)];
    edge.e = x(j + 1) - x(j);
    edge.length = edge.e.norm();
    MaterialFrame(frames.frames[static_cast<size_t>(j)], q(o + TwistDof(j)), &edge.m1, &edge.m2);
    energy += StretchingEnergy({rod.axial_stiffness, rod.rest_edge_length(j)}, x(j), x(j + 1),
                               &g6, hessian ? &h6 : nullptr);
    force->segment<3>(o + NodeDof(j)) -= g6.head<3>();
    force->segment<3>(o + NodeDof(j + 1)) -= g6.tail<3>();
    if (hessian) AddStretchingBlocks(NodeDof(j), NodeDof(j + 1), h6, hessian);
  }
  for (int i = 1; i + 1 < n; ++i) {
    const EdgeTerms& a = edges[static_cast<size_t>(i - 1)];
    const EdgeTerms& b = edges[static_cast<size_t>(i)];
    const double dl = rod.rest_voronoi_length(i);
    const double d = a.length * b.length + a.e.dot(b.e);
    SR_DASSERT(d > 1e-14 * a.length * b.length, "curvature binormal of anti-parallel edges");
    const Vec3 kb = (2.0 / d) * a.e.cross(b.e);
    // Bending: κ⁽¹⁾ = ½ (m2⁰ + m2¹)·κb, κ⁽²⁾ = −½ (m1⁰ + m1¹)·κb (paper eq. 3).
    const double bend = rod.bending_stiffness / dl;
    const Vec3 m1 = a.m1 + b.m1, m2 = a.m2 + b.m2;
    const Vec2 excess = Vec2(0.5 * m2.dot(kb), -0.5 * m1.dot(kb)) -
                        rod.rest_curvature[static_cast<size_t>(i)];
    energy += 0.5 * bend * excess.squaredNorm();
    // Twisting: τ = θ1 − θ0 + m_ref (paper eq. 4), ∂m_ref/∂e_j = κb / (2|e_j|).
    const double twist_stiffness = rod.twisting_stiffness / dl;
    const double twist = q(o + TwistDof(i)) - q(o + TwistDof(i - 1)) +
                         frames.reference_twist(i) - rod.rest_twist(i);
    energy += 0.5 * twist_stiffness * twist * twist;
    const double twist_moment = twist_stiffness * twist;
    // The gradient in (e0, θ0, e1, θ1).
    const Vec3 w = (0.5 * bend) * (excess[0] * m2 - excess[1] * m1);
    const double kb_w = kb.dot(w) / d;
    Vec8 g;
    g << (2.0 / d) * b.e.cross(w) - kb_w * ((b.length / a.length) * a.e + b.e) +
             (0.5 * twist_moment / a.length) * kb,
        -0.5 * bend * (excess[0] * a.m1.dot(kb) + excess[1] * a.m2.dot(kb)) - twist_moment,
        (2.0 / d) * w.cross(a.e) - kb_w * ((a.length / b.length) * b.e + a.e) +
            (0.5 * twist_moment / b.length) * kb,
        -0.5 * bend * (excess[0] * b.m1.dot(kb) + excess[1] * b.m2.dot(kb)) + twist_moment;
    const int first = NodeDof(i - 1);  // the stencil is 11 consecutive DOFs
    force->segment<11>(o + first) -= EdgeToStencilGradient(g);
    if (hessian)
      hessian->AddBlock(first, EdgeToStencilHessian(StencilJacobian(
                                   a, b, bend, excess, twist_stiffness, twist_moment)));
  }
  return energy;
}

}  // namespace

double AddElasticForces(const RodModel& rod, const VecX& q, const RodFrames& frames, VecX* force,
                        BandedMatrix* hessian) {
  if (force) return AddElasticForcesByEdge(rod, q, frames, force, hessian);
  return AddElasticForcesPerStencil(rod, q, frames, force, hessian);
}

double AddElasticForcesPerStencil(const RodModel& rod, const VecX& q, const RodFrames& frames,
                                  VecX* force, BandedMatrix* hessian) {
  const int n = rod.num_nodes();
  const int o = rod.dof_offset;
  auto x = [&](int i) { return Vec3(q.segment<3>(o + NodeDof(i))); };
  const bool want_gradient = force != nullptr || hessian != nullptr;
  double energy = 0.0;

  Vec6 g6;
  Mat6 h6;
  for (int j = 0; j + 1 < n; ++j) {  // stretching of edge j: DOFs (x_j, x_{j+1})
    const StretchingParams p{rod.axial_stiffness, rod.rest_edge_length(j)};
    energy += StretchingEnergy(p, x(j), x(j + 1), want_gradient ? &g6 : nullptr,
                               hessian ? &h6 : nullptr);
    const int a = NodeDof(j), b = NodeDof(j + 1);
    if (force) {
      force->segment<3>(o + a) -= g6.head<3>();
      force->segment<3>(o + b) -= g6.tail<3>();
    }
    if (hessian) AddStretchingBlocks(a, b, h6, hessian);
  }

  // Bending and twisting at node i share the curvature of the stencil (DOFs 4(i−1) … 4(i+1)+2)
  // and are summed in the edge variables, then mapped to the stencil once.
  Vec8 bend_g, twist_g;
  Mat8 bend_h, twist_h;
  for (int i = 1; i + 1 < n; ++i) {
    const double dl = rod.rest_voronoi_length(i);
    const double theta0 = q(o + TwistDof(i - 1)), theta1 = q(o + TwistDof(i));
    const StencilCurvature c = CalcStencilCurvature(x(i) - x(i - 1), x(i + 1) - x(i), want_gradient);
    const BendingParams bp{rod.bending_stiffness / dl, rod.rest_curvature[i]};
    energy += BendingEdgeEnergy(bp, c, frames.frames[i - 1], frames.frames[i], theta0, theta1,
                                want_gradient ? &bend_g : nullptr, hessian ? &bend_h : nullptr);
    const TwistingParams tp{rod.twisting_stiffness / dl, rod.rest_twist(i)};
    energy += TwistingEdgeEnergy(tp, c, theta0, theta1, frames.reference_twist(i),
                                 want_gradient ? &twist_g : nullptr, hessian ? &twist_h : nullptr);
    const int first = NodeDof(i - 1);  // the stencil is 11 consecutive DOFs
    if (force) force->segment<11>(o + first) -= EdgeToStencilGradient(bend_g + twist_g);
    if (hessian) hessian->AddBlock(first, EdgeToStencilHessian(bend_h + twist_h));
  }
  return energy;
}

}  // namespace stokesrods
