#include "stokesrods/sim/elastic_assembly.h"

#include <algorithm>
#include <vector>

#include "stokesrods/common/assert.h"
#include "stokesrods/elastic/bending.h"
#include "stokesrods/elastic/stencil_batch.h"
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

// The forces, and the Jacobian where `hessian` is given, by edges: each edge's vector, length and
// material directors are computed once (one sine and one cosine per edge, where the stencils'
// own calls take two per stencil; several edges per vector: MaterialFrames) into columns, and
// the bending and twisting of all stencils are then computed several at a time, one per vector
// lane (elastic/stencil_batch.h; the formulas in elastic/stencil_lanes.h). The arithmetic of
// StretchingEnergy, BendingEdgeEnergy and TwistingEdgeEnergy otherwise; ElasticAssembly.*
// (tests/sim/jacobian_test.cc) compares it with AddElasticForcesPerStencil on every instruction
// set.
double AddElasticForcesByEdge(const RodModel& rod, const VecX& q, const RodFrames& frames,
                              VecX* force, BandedMatrix* hessian, StencilPath path) {
  const int n = rod.num_nodes();
  const int o = rod.dof_offset;
  auto x = [&](int i) { return Vec3(q.segment<3>(o + NodeDof(i))); };
  double energy = 0.0;
  // Kept: no allocation per evaluation. Columns of the edges and of the stencils, by first column:
  enum EdgeColumn { kEdge = 0, kLength = 3, kM1 = 4, kM2 = 7, kTheta = 10, kD1 = 11, kD2 = 14,
                    kEdgeColumns = 17 };
  enum StencilColumn { kKb = 0, kD = 3, kExcess = 4, kBend = 6, kTwistStiffness = 7, kTwist = 8,
                       kStencilColumns = 9 };
  thread_local std::vector<double> edge_columns, stencil_columns;
  thread_local StencilResults results;
  const auto edges = static_cast<size_t>(n - 1), stencils = static_cast<size_t>(std::max(n - 2, 0));
  edge_columns.resize(kEdgeColumns * edges);
  stencil_columns.resize(kStencilColumns * stencils);
  auto edge_column = [&](int k) { return edge_columns.data() + k * edges; };
  auto stencil_column = [&](int k) { return stencil_columns.data() + k * stencils; };
  MaterialFrameColumns material;
  material.theta = edge_column(kTheta);
  for (int j = 0; j + 1 < n; ++j) {
    const RefFrame& f = frames.frames[static_cast<size_t>(j)];
    edge_column(kTheta)[j] = q(o + TwistDof(j));
    for (int c = 0; c < 3; ++c)
      edge_column(kD1 + c)[j] = f.d1[c], edge_column(kD2 + c)[j] = f.d2[c];
  }
  for (int c = 0; c < 3; ++c) {
    material.d1[c] = edge_column(kD1 + c);
    material.d2[c] = edge_column(kD2 + c);
    material.m1[c] = edge_column(kM1 + c);
    material.m2[c] = edge_column(kM2 + c);
  }
  MaterialFrames(material, n - 1, path);
  Vec6 g6;
  Mat6 h6;
  for (int j = 0; j + 1 < n; ++j) {
    const Vec3 e = x(j + 1) - x(j);
    for (int c = 0; c < 3; ++c) edge_column(kEdge + c)[j] = e[c];
    edge_column(kLength)[j] = e.norm();
    energy += StretchingEnergy({rod.axial_stiffness, rod.rest_edge_length(j)}, x(j), x(j + 1),
                               &g6, hessian ? &h6 : nullptr);
    force->segment<3>(o + NodeDof(j)) -= g6.head<3>();
    force->segment<3>(o + NodeDof(j + 1)) -= g6.tail<3>();
    if (hessian) AddStretchingBlocks(NodeDof(j), NodeDof(j + 1), h6, hessian);
  }
  auto edge_vector = [&](int first_column, int j) {
    return Vec3(edge_column(first_column)[j], edge_column(first_column + 1)[j],
                edge_column(first_column + 2)[j]);
  };
  for (int i = 1; i + 1 < n; ++i) {
    const int s = i - 1;
    // κb and Δκ in the arithmetic of the rest curvature (MaterialCurvatures), so that they vanish
    // exactly at rest; the lanes take them from here.
    const Vec3 e0 = edge_vector(kEdge, s), e1 = edge_vector(kEdge, i);
    const double l0 = edge_column(kLength)[s], l1 = edge_column(kLength)[i];
    const double d = l0 * l1 + e0.dot(e1);
    SR_DASSERT(d > 1e-14 * l0 * l1,
               "curvature binormal of anti-parallel edges");
    const Vec3 kb = (2.0 / d) * e0.cross(e1);
    const Vec3 m1 = edge_vector(kM1, s) + edge_vector(kM1, i);
    const Vec3 m2 = edge_vector(kM2, s) + edge_vector(kM2, i);
    const Vec2 excess =
        Vec2(0.5 * m2.dot(kb), -0.5 * m1.dot(kb)) - rod.rest_curvature[static_cast<size_t>(i)];
    const double dl = rod.rest_voronoi_length(i);
    for (int c = 0; c < 3; ++c) stencil_column(kKb + c)[s] = kb[c];
    stencil_column(kD)[s] = d;
    stencil_column(kExcess)[s] = excess[0];
    stencil_column(kExcess + 1)[s] = excess[1];
    stencil_column(kBend)[s] = rod.bending_stiffness / dl;
    stencil_column(kTwistStiffness)[s] = rod.twisting_stiffness / dl;
    stencil_column(kTwist)[s] = q(o + TwistDof(i)) - q(o + TwistDof(i - 1)) +
                                frames.reference_twist(i) - rod.rest_twist(i);
  }
  StencilColumns in;
  for (int c = 0; c < 3; ++c) {
    in.edge[c] = edge_column(kEdge + c);
    in.m1[c] = edge_column(kM1 + c);
    in.m2[c] = edge_column(kM2 + c);
    in.curvature_binormal[c] = stencil_column(kKb + c);
  }
  in.length = edge_column(kLength);
  in.denominator = stencil_column(kD);
  in.excess[0] = stencil_column(kExcess);
  in.excess[1] = stencil_column(kExcess + 1);
  in.bend = stencil_column(kBend);
  in.twist_stiffness = stencil_column(kTwistStiffness);
  in.twist = stencil_column(kTwist);
  BendTwistStencils(in, static_cast<int>(stencils), hessian != nullptr, &results, path);
  for (int i = 1; i + 1 < n; ++i) {
    const auto s = static_cast<size_t>(i - 1);
    const int first = NodeDof(i - 1);  // the stencil is 11 consecutive DOFs
    energy += results.energy[s];
    force->segment<11>(o + first) -= Eigen::Map<const Vec11>(results.gradient.data() + 11 * s);
    if (hessian)
      hessian->AddBlock(first, Eigen::Map<const Mat11>(results.jacobian.data() + 121 * s));
  }
  return energy;
}

}  // namespace

double AddElasticForces(const RodModel& rod, const VecX& q, const RodFrames& frames, VecX* force,
                        BandedMatrix* hessian, StencilPath path) {
  if (force) return AddElasticForcesByEdge(rod, q, frames, force, hessian, path);
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
