// Semantic checks of a configuration whose types are already right (config.cc reads the types).
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "stokesrods/io/config.h"

namespace stokesrods {
namespace {

struct Checker {
  const std::string& file;

  void Positive(const std::string& key, double v) const {
    if (!(v > 0.0) || !std::isfinite(v))
      throw ConfigError(file, key, fmt::format("must be a finite number > 0 (got {})", v));
  }
  void NonNegative(const std::string& key, double v) const {
    if (!(v >= 0.0) || !std::isfinite(v))
      throw ConfigError(file, key, fmt::format("must be a finite number ≥ 0 (got {})", v));
  }
  void OneOf(const std::string& key, const std::string& v, const std::set<std::string>& allowed) const {
    if (allowed.count(v) != 0) return;
    std::string list;
    for (const std::string& a : allowed) list += (list.empty() ? "\"" : ", \"") + a + "\"";
    throw ConfigError(file, key, fmt::format("\"{}\" is not one of {}", v, list));
  }
  void Range(const std::string& key, int v, int lo, int hi) const {
    if (v < lo || v > hi)
      throw ConfigError(file, key, fmt::format("must be between {} and {} (got {})", lo, hi, v));
  }
  void Finite(const std::string& key, const Vec3& v) const {
    if (!v.allFinite()) throw ConfigError(file, key, "must be finite");
  }
};

void ValidateRod(const Checker& c, const std::string& p, RodConfig* rod) {
  c.OneOf(p + ".shape", rod->shape, {"helix", "straight", "points"});
  c.Positive(p + ".radius", rod->radius);
  c.Positive(p + ".young_modulus", rod->young_modulus);
  if (!(rod->poisson_ratio > -1.0 && rod->poisson_ratio <= 0.5))
    throw ConfigError(c.file, p + ".poisson_ratio",
                      fmt::format("must lie in (−1, 0.5] (got {})", rod->poisson_ratio));
  c.Positive(p + ".density", rod->density);
  c.Finite(p + ".base", rod->base);
  c.OneOf(p + ".handedness", rod->handedness, {"right", "left"});
  c.OneOf(p + ".lead_in", rod->lead_in, {"within", "above"});
  c.Range(p + ".clamped_nodes", rod->clamped_nodes, 0, 2);
  if (rod->shape == "points") {
    if (rod->points.size() < 3)
      throw ConfigError(c.file, p + ".points", "shape = \"points\" needs at least 3 points");
    for (std::size_t i = 0; i + 1 < rod->points.size(); ++i)
      if ((rod->points[i + 1] - rod->points[i]).norm() <= 0.0)
        throw ConfigError(c.file, fmt::format("{}.points[{}]", p, i + 1),
                          "repeats the previous point (zero-length edge)");
    rod->nodes = static_cast<int>(rod->points.size());
    // l0 of a points rod: its end-to-end distance at rest (used for normalizations).
    rod->axis_length = (rod->points.back() - rod->points.front()).norm();
  } else {
    if (!rod->points.empty())
      throw ConfigError(c.file, p + ".points", "only for shape = \"points\"");
    c.Positive(p + ".axis_length", rod->axis_length);
    c.Range(p + ".nodes", rod->nodes, rod->shape == "helix" ? 5 : 3, 1000000);
  }
  if (rod->shape == "helix") {
    c.Positive(p + ".pitch", rod->pitch);
    c.Positive(p + ".helix_radius", rod->helix_radius);
    if (rod->axis_length <= 2.0 * rod->helix_radius)
      throw ConfigError(c.file, p + ".axis_length",
                        "must exceed twice helix_radius (the first two edges take R + one spacing)");
  }
  if (rod->omega && rod->omega_bar)
    throw ConfigError(c.file, p + ".omega_bar", "give omega or omega_bar, not both");
  const double rate = rod->omega ? *rod->omega : rod->omega_bar ? *rod->omega_bar : 0.0;
  if (!std::isfinite(rate))
    throw ConfigError(c.file, p + (rod->omega ? ".omega" : ".omega_bar"), "must be finite");
  if (rate != 0.0 && rod->clamped_nodes < 2)
    throw ConfigError(c.file, p + (rod->omega ? ".omega" : ".omega_bar"),
                      "a rotation needs clamped_nodes = 2 (it drives the first twist angle)");
  for (std::size_t i = 0; i < rod->loads.size(); ++i) {
    const std::string key = fmt::format("{}.loads[{}]", p, i);
    c.Range(key + ".node", rod->loads[i].node, 0, rod->nodes - 1);
    c.Finite(key + ".force", rod->loads[i].force);
  }
}

}  // namespace

void ValidateBodiesAndWall(Config* config);  // config_bodies.cc

void ValidateConfig(Config* config) {
  const Checker c{config->file};
  RunConfig& run = config->run;
  c.OneOf("run.mode", run.mode, {"dynamic", "static"});
  c.OneOf("run.integrator", run.integrator, {"euler", "bdf2"});
  c.OneOf("run.frames_format", run.frames_format, {"ascii", "binary", "appended"});
  if (run.integrator == "bdf2" && config->fluid.coupling == "explicit")
    throw ConfigError(c.file, "run.integrator",
                      "\"bdf2\" needs fluid.coupling = \"implicit\" (the explicit drag is first order)");
  if (run.name.empty()) throw ConfigError(c.file, "run.name", "must not be empty");
  if (run.output.empty()) run.output = "out/" + run.name;
  c.Positive("run.time_step", run.time_step);
  if (run.mode == "dynamic") {
    if (run.duration.has_value() == run.t_bar_end.has_value())
      throw ConfigError(c.file, "run.duration",
                        "a dynamic run needs exactly one of run.duration and run.t_bar_end");
    if (run.duration) c.Positive("run.duration", *run.duration);
    if (run.t_bar_end) c.Positive("run.t_bar_end", *run.t_bar_end);
  }
  if (run.output_interval) c.Positive("run.output_interval", *run.output_interval);
  if (run.checkpoint_interval) c.Positive("run.checkpoint_interval", *run.checkpoint_interval);
  if (run.checkpoint_wall_interval)
    c.Positive("run.checkpoint_wall_interval", *run.checkpoint_wall_interval);
  if (run.stop_when_buckled && (run.mode != "dynamic" || config->rods.empty() ||
                                config->rods[0].shape != "helix"))
    throw ConfigError(c.file, "run.stop_when_buckled",
                      "needs a dynamic run whose rod 1 is a helix (the rule measures its helix radius)");

  c.OneOf("fluid.model", config->fluid.model, {"rss", "lsbt", "rft", "none"});
  c.OneOf("fluid.coupling", config->fluid.coupling, {"implicit", "explicit"});
  c.Positive("fluid.viscosity", config->fluid.viscosity);
  c.Positive("fluid.regularization", config->fluid.regularization);
  c.OneOf("fluid.mobility", config->fluid.mobility, {"auto", "dense", "matrix_free"});
  if (config->fluid.mobility == "matrix_free" && config->fluid.model != "rss")
    throw ConfigError(c.file, "fluid.mobility",
                      "\"matrix_free\" is implemented for fluid.model = \"rss\" only");
  c.OneOf("fluid.solver", config->fluid.solver, {"krylov", "direct"});
  if (config->fluid.solver == "direct" && config->fluid.mobility == "matrix_free")
    throw ConfigError(c.file, "fluid.solver",
                      "\"direct\" needs the dense mobility (fluid.mobility = \"dense\")");
  c.Positive("fluid.far_field_tolerance", config->fluid.far_field_tolerance);
  c.Positive("fluid.krylov_tolerance", config->fluid.krylov_tolerance);
  c.Range("fluid.krylov_coarse_rebuild_period", config->fluid.krylov_coarse_rebuild_period, 0,
          1000000);
  if (config->fluid.far_field_tolerance >= 1e-2)
    throw ConfigError(c.file, "fluid.far_field_tolerance", "must be below 1e-2");
  c.Positive("fluid.fast_sum_tolerance", config->fluid.fast_sum_tolerance);
  if (config->fluid.fast_sum_tolerance >= 1e-2)
    throw ConfigError(c.file, "fluid.fast_sum_tolerance", "must be below 1e-2");
  c.NonNegative("fluid.mobility_reuse_tolerance", config->fluid.mobility_reuse_tolerance);
  if (config->fluid.mobility_reuse_tolerance >= 1e-2)
    throw ConfigError(c.file, "fluid.mobility_reuse_tolerance", "must be below 1e-2");
  if (config->fluid.krylov_tolerance >= 1e-2)
    throw ConfigError(c.file, "fluid.krylov_tolerance", "must be below 1e-2");
  c.Positive("contact.tolerance", config->contact.tolerance);
  c.Range("contact.max_rounds", config->contact.max_rounds, 1, 100000);
  c.Finite("gravity.acceleration", config->gravity.acceleration);
  c.Positive("solver.newton_tolerance", config->solver.newton_tolerance);
  c.Range("solver.newton_max_iterations", config->solver.newton_max_iterations, 1, 10000);
  c.Range("solver.jacobian_max_age", config->solver.jacobian_max_age, 0, 1000000);
  c.NonNegative("solver.damping", config->solver.damping);
  c.Range("solver.max_step_halvings", config->solver.max_step_halvings, 0, 20);

  const FlowFieldConfig& flow = config->flow_field;
  for (std::size_t i = 0; i < flow.times.size(); ++i)
    c.NonNegative(fmt::format("flow_field.times[{}]", i), flow.times[i]);
  c.Finite("flow_field.origin", flow.origin);
  c.Finite("flow_field.u", flow.u);
  c.Finite("flow_field.v", flow.v);
  if (flow.resolution.size() != 2)
    throw ConfigError(c.file, "flow_field.resolution", "expected two integers [along u, along v]");
  c.Range("flow_field.resolution[0]", flow.resolution[0], 2, 100000);
  c.Range("flow_field.resolution[1]", flow.resolution[1], 2, 100000);
  if (!flow.times.empty() && flow.u.cross(flow.v).norm() == 0.0)
    throw ConfigError(c.file, "flow_field.v", "the plane's edges u and v must not be parallel");
  if (!flow.times.empty() && config->fluid.model == "none")
    throw ConfigError(c.file, "flow_field.times", "a flow field needs a fluid model");

  if (config->rods.empty() && config->bodies.empty())
    throw ConfigError(c.file, "rods", "at least one [[rods]] (or [[bodies]]) is required");
  if (config->rods.empty() && run.t_bar_end)
    throw ConfigError(c.file, "run.t_bar_end", "needs a rod (its time scale μ l0⁴/EI); give run.duration");
  for (std::size_t i = 0; i < config->rods.size(); ++i)
    ValidateRod(c, fmt::format("rods.{}", i + 1), &config->rods[i]);
  ValidateBodiesAndWall(config);
}

}  // namespace stokesrods
