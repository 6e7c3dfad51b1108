// [[bodies]] and [wall] into the model (SPEC "Additions"), with the checks that need the rods'
// shapes: nothing may cross the wall or overlap a body at the start.
#pragma once

#include "stokesrods/io/config.h"
#include "stokesrods/sim/model.h"

namespace stokesrods {

/// Throws ConfigError when a rod or a body crosses or touches the wall, bodies overlap each other,
/// or a rod enters a body (a rod on body K: beyond its clamped edge; its node 0 must lie on K's
/// surface within one edge length).
void CheckBodiesAndWall(const Config& config, const Model& model);

/// The blob of a body's surface Stokeslets over their spacing √(area/N): 0.3 balances the
/// errors of drag and torque (docs/validation.md, tests/fluid/rigid_body_test.cc).
constexpr double kBodyBlobOverSpacing = 0.3;

/// Appends the bodies of the configuration to the model (call before FinalizeLayout).
void AddBodies(const Config& config, Model* model);

}  // namespace stokesrods
