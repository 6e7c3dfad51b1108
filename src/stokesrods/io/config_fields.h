// The field lists of the configuration structs (config.h): one VisitFields per struct, the single
// list that drives the reader, the writers and the key list (config.cc). Internal to io/.
#pragma once

#include "stokesrods/io/config.h"

namespace stokesrods {

template <class V>
void VisitFields(RunConfig& c, V& v) {
  v("name", c.name);
  v("output", c.output);
  v("mode", c.mode);
  v("duration", c.duration);
  v("t_bar_end", c.t_bar_end);
  v("time_step", c.time_step);
  v("integrator", c.integrator);
  v("output_interval", c.output_interval);
  v("frames", c.frames);
  v("frames_format", c.frames_format);
  v("checkpoint_interval", c.checkpoint_interval);
  v("checkpoint_wall_interval", c.checkpoint_wall_interval);
  v("stop_when_buckled", c.stop_when_buckled);
}
template <class V>
void VisitFields(FluidConfig& c, V& v) {
  v("model", c.model);
  v("viscosity", c.viscosity);
  v("regularization", c.regularization);
  v("coupling", c.coupling);
  v("mobility", c.mobility);
  v("far_field_tolerance", c.far_field_tolerance);
  v("fast_sum_tolerance", c.fast_sum_tolerance);
  v("mobility_reuse_tolerance", c.mobility_reuse_tolerance);
  v("solver", c.solver);
  v("krylov_tolerance", c.krylov_tolerance);
  v("krylov_rotate_preconditioner", c.krylov_rotate_preconditioner);
  v("krylov_coarse_rebuild_period", c.krylov_coarse_rebuild_period);
}
template <class V>
void VisitFields(ContactConfig& c, V& v) {
  v("enabled", c.enabled);
  v("tolerance", c.tolerance);
  v("max_rounds", c.max_rounds);
}
template <class V>
void VisitFields(GravityConfig& c, V& v) {
  v("acceleration", c.acceleration);
}
template <class V>
void VisitFields(SolverConfig& c, V& v) {
  v("newton_tolerance", c.newton_tolerance);
  v("newton_max_iterations", c.newton_max_iterations);
  v("jacobian_max_age", c.jacobian_max_age);
  v("damping", c.damping);
  v("max_step_halvings", c.max_step_halvings);
}
template <class V>
void VisitFields(FlowFieldConfig& c, V& v) {
  v("times", c.times);
  v("origin", c.origin);
  v("u", c.u);
  v("v", c.v);
  v("resolution", c.resolution);
}
template <class V>
void VisitFields(PointLoadConfig& c, V& v) {
  v("node", c.node);
  v("force", c.force);
}
template <class V>
void VisitFields(RodConfig& c, V& v) {
  v("shape", c.shape);
  v("radius", c.radius);
  v("young_modulus", c.young_modulus);
  v("poisson_ratio", c.poisson_ratio);
  v("density", c.density);
  v("nodes", c.nodes);
  v("axis_length", c.axis_length);
  v("pitch", c.pitch);
  v("helix_radius", c.helix_radius);
  v("handedness", c.handedness);
  v("lead_in", c.lead_in);
  v("base", c.base);
  v("clamped_nodes", c.clamped_nodes);
  v("omega", c.omega);
  v("omega_bar", c.omega_bar);
  v("points", c.points);
  v("loads", c.loads);
  v("body", c.body);
}

template <class V>
void VisitFields(BodyConfig& c, V& v) {
  v("shape", c.shape);
  v("radius", c.radius);
  v("half_length", c.half_length);
  v("axis", c.axis);
  v("center", c.center);
  v("motion", c.motion);
  v("velocity", c.velocity);
  v("angular_velocity", c.angular_velocity);
  v("force", c.force);
  v("torque", c.torque);
  v("surface_points", c.surface_points);
}
template <class V>
void VisitFields(WallConfig& c, V& v) {
  v("point", c.point);
  v("normal", c.normal);
}

}  // namespace stokesrods
