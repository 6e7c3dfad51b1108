// The mutable state of a simulation (MuJoCo's mjData without scratch): what a checkpoint saves.
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/rod/frames.h"
#include "stokesrods/sim/model.h"

namespace stokesrods {

/// Reference frames of one rod, carried in time by parallel transport.
struct RodFrames {
  std::vector<RefFrame> frames;   ///< per edge
  std::vector<Vec3> tangents;     ///< per edge, the tangents the frames are attached to
  VecX reference_twist;           ///< per node (interior used) [rad]
};

/// Where a rigid body is: its centre and its rotation from the body's rest frame.
struct BodyPose {
  Vec3 center = Vec3::Zero();
  Mat3 rotation = Mat3::Identity();
};

struct State {
  double time = 0.0;     ///< [s]
  long step = 0;
  VecX q;                ///< all DOFs of all rods
  VecX velocity;         ///< dq/dt
  std::vector<RodFrames> rods;
  std::vector<BodyPose> bodies;   ///< one per model body
};

/// Node positions of rod r of the global vector q (3 × N).
Matrix3X RodPositions(const Model& model, int r, const VecX& q);

/// The state at rest: q from the rest shapes (θ = 0), zero velocity, space-parallel frames.
State MakeRestState(const Model& model);

/// Frames of every rod carried from `from` to the positions in q (time-parallel transport), and
/// the reference twists recomputed with continuity from `from`.
void TransportFrames(const Model& model, const VecX& q, const std::vector<RodFrames>& from,
                     std::vector<RodFrames>* to);

}  // namespace stokesrods
