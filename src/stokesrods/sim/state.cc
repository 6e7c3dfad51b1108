#include "stokesrods/sim/state.h"

#include "stokesrods/common/parallel.h"

namespace stokesrods {

Matrix3X RodPositions(const Model& model, int r, const VecX& q) {
  const RodModel& rod = model.rods[r];
  Matrix3X x(3, rod.num_nodes());
  for (int i = 0; i < rod.num_nodes(); ++i) x.col(i) = q.segment<3>(rod.dof_offset + NodeDof(i));
  return x;
}

State MakeRestState(const Model& model) {
  State state;
  state.q = VecX::Zero(model.num_dofs);
  state.velocity = VecX::Zero(model.num_dofs);
  for (const RodModel& rod : model.rods) {
    for (int i = 0; i < rod.num_nodes(); ++i)
      state.q.segment<3>(rod.dof_offset + NodeDof(i)) = rod.rest_positions.col(i);
    RodFrames frames;
    frames.frames = SpaceParallelFrames(rod.rest_positions);
    frames.tangents = EdgeTangents(rod.rest_positions);
    frames.reference_twist = ReferenceTwists(frames.frames, frames.tangents, VecX());
    state.rods.push_back(std::move(frames));
  }
  for (const BodyModel& body : model.bodies) state.bodies.push_back({body.center, Mat3::Identity()});
  return state;
}

void TransportFrames(const Model& model, const VecX& q, const std::vector<RodFrames>& from,
                     std::vector<RodFrames>* to) {
  to->resize(from.size());
  const int num_rods = static_cast<int>(from.size());
  ForEachDynamic(num_rods, RodsInParallel(num_rods, model.num_nodes), [&](int ri) {
    const auto r = static_cast<std::size_t>(ri);
    RodFrames& out = (*to)[r];
    out.frames = from[r].frames;
    out.tangents = from[r].tangents;
    const Matrix3X x = RodPositions(model, static_cast<int>(r), q);
    TransportFramesAndTwists(x, &out.tangents, &out.frames, from[r].reference_twist,
                             &out.reference_twist);
  });
}

}  // namespace stokesrods
