#include "stokesrods/sim/model.h"

#include <algorithm>
#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/elastic/bending.h"
#include "stokesrods/rod/frames.h"

namespace stokesrods {

void FinalizeRod(RodModel* rod) {
  const Matrix3X& x = rod->rest_positions;
  const int n = rod->num_nodes();
  SR_ASSERT(n >= 3, "a rod needs at least 3 nodes");
  rod->rest_edge_length.resize(n - 1);
  for (int i = 0; i + 1 < n; ++i) rod->rest_edge_length(i) = (x.col(i + 1) - x.col(i)).norm();
  rod->rest_voronoi_length = VecX::Zero(n);
  for (int i = 0; i + 1 < n; ++i) {
    rod->rest_voronoi_length(i) += 0.5 * rod->rest_edge_length(i);
    rod->rest_voronoi_length(i + 1) += 0.5 * rod->rest_edge_length(i);
  }

  // Lumped masses: ρ A Δl_i on each node, ρ J |ē^j| (= ½ m_edge r0²) on each twist angle.
  const double area = kPi * rod->radius * rod->radius;
  const double polar = 0.5 * kPi * std::pow(rod->radius, 4);
  rod->mass.resize(rod->num_dofs());
  for (int i = 0; i < n; ++i)
    rod->mass.segment<3>(NodeDof(i)).setConstant(rod->density * area * rod->rest_voronoi_length(i));
  for (int j = 0; j + 1 < n; ++j)
    rod->mass(TwistDof(j)) = rod->density * polar * rod->rest_edge_length(j);

  // Rest curvatures and twist: those of the rest shape with its space-parallel frames and θ = 0,
  // the same frames the rest state starts from (MakeRestState), so the rest shape is stress-free.
  const std::vector<RefFrame> frames = SpaceParallelFrames(x);
  const std::vector<Vec3> tangents = EdgeTangents(x);
  rod->rest_curvature.assign(n, Vec2::Zero());
  for (int i = 1; i + 1 < n; ++i) {
    rod->rest_curvature[i] = MaterialCurvatures(x.col(i - 1), x.col(i), x.col(i + 1),
                                                frames[i - 1], frames[i], 0.0, 0.0);
  }
  rod->rest_twist = ReferenceTwists(frames, tangents, VecX());

  rod->fixed_dofs.clear();
  if (rod->clamped_nodes >= 1)
    for (int k = 0; k < 3; ++k) rod->fixed_dofs.push_back(NodeDof(0) + k);
  if (rod->clamped_nodes >= 2) {
    rod->fixed_dofs.push_back(TwistDof(0));
    for (int k = 0; k < 3; ++k) rod->fixed_dofs.push_back(NodeDof(1) + k);
  }
  std::sort(rod->fixed_dofs.begin(), rod->fixed_dofs.end());
}

void FinalizeLayout(Model* model) {
  int dofs = 0, nodes = 0;
  double force_scale = 0.0;
  for (RodModel& rod : model->rods) {
    rod.dof_offset = dofs;
    rod.node_offset = nodes;
    dofs += rod.num_dofs();
    nodes += rod.num_nodes();
    const double length = rod.rest_edge_length.sum();
    force_scale = std::max(force_scale, rod.bending_stiffness / (length * length));
    model->length_scale = std::max(model->length_scale, length);
    model->max_voronoi_length =
        std::max(model->max_voronoi_length, rod.rest_voronoi_length.maxCoeff());
  }
  model->num_dofs = dofs;
  model->num_nodes = nodes;
  model->force_scale = force_scale;
  int points = 0;
  model->num_free_bodies = 0;
  for (BodyModel& body : model->bodies) {
    body.point_offset = points;
    body.free_index = body.motion == BodyMotion::kFree ? model->num_free_bodies++ : -1;
    points += body.num_points();
    // Without rods the bodies set the scales: their size and their Stokes drag or own load.
    if (!model->rods.empty()) continue;
    model->length_scale = std::max(model->length_scale, 2.0 * body.radius);
    model->max_voronoi_length = std::max(model->max_voronoi_length, body.regularization);
    model->force_scale = std::max({model->force_scale,
                                   6.0 * kPi * model->fluid.viscosity * body.radius *
                                       (body.velocity.norm() + body.radius * body.angular_velocity.norm()),
                                   body.force.norm() + body.torque.norm() / body.radius});
  }
  model->num_body_points = points;
}

}  // namespace stokesrods
