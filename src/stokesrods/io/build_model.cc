#include "stokesrods/io/build_model.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "stokesrods/fluid/lsbt.h"
#include "stokesrods/sim/observables.h"
#include "stokesrods/fluid/rft.h"
#include "stokesrods/rod/geometry.h"
#include "stokesrods/solver/dense_lu.h"
#include "stokesrods/solver/dense_spectral.h"
#include "stokesrods/sim/hydro_coupling.h"
#include "stokesrods/sim/contact_forces.h"
#include "stokesrods/sim/observables.h"
#include "stokesrods/sim/state.h"
#include "stokesrods/io/build_bodies.h"
#include "stokesrods/io/rest_shape.h"

namespace stokesrods {
namespace {

FluidModel ParseFluidModel(const std::string& name) {
  if (name == "rss") return FluidModel::kRss;
  if (name == "lsbt") return FluidModel::kLsbt;
  if (name == "rft") return FluidModel::kRft;
  return FluidModel::kNone;
}

// RFT coefficients, the LSBT discretization, the stability of the explicit coupling.
// A node count whose rest shape fits LSBT (at most `allowed` edges off), or 0. The helix's
// spacing depends on N through its lead-in, so the arc length over 2δ alone can miss; the edges
// shrink as N grows, so a bisection finds the first N whose last edge is no longer than 2δ, and
// the counts around it are checked in full (about 20 shapes built, whatever the size).
int FittingLsbtNodes(RodConfig rc, int estimate, int allowed) {
  const double target = LsbtEdgeLength(rc.radius);
  auto last_edge = [&](int n) {
    rc.nodes = n;
    const Matrix3X x = RestShape(rc);
    return (x.col(n - 1) - x.col(n - 2)).norm();
  };
  const int fewest = rc.shape == "helix" ? 5 : 3;
  int lo = fewest;
  int hi = static_cast<int>(std::min<long long>(1000000, std::max<long long>(64, 4LL * estimate)));
  if (last_edge(hi) > target) return 0;
  while (lo < hi) {
    const int mid = lo + (hi - lo) / 2;
    if (last_edge(mid) <= target)
      hi = mid;
    else
      lo = mid + 1;
  }
  for (int n : {lo, lo - 1, lo + 1, lo - 2, lo + 2}) {
    if (n < fewest) continue;
    rc.nodes = n;
    if (CheckLsbtDiscretization(RestShape(rc), rc.radius).edges_outside <= allowed) return n;
  }
  return 0;
}

void CheckFluidModel(const Config& config, Model* model) {
  for (std::size_t r = 0; r < model->rods.size(); ++r) {
    RodModel& rod = model->rods[r];
    const RodConfig& rc = config.rods[r];
    const std::string key = fmt::format("rods.{}", r + 1);
    if (model->fluid.model == FluidModel::kRft) {
      // Lighthill's coefficients with the wavelength along the filament: one helical turn, or
      // the whole rod for other shapes.
      const double wavelength = rc.shape == "helix"
                                    ? std::hypot(rc.pitch, 2.0 * kPi * rc.helix_radius)
                                    : rod.rest_edge_length.sum();
      try {
        const RftCoefficients c = LighthillCoefficients(model->fluid.viscosity, rod.radius, wavelength);
        rod.rft_coefficients = Vec2(c.parallel, c.perpendicular);
      } catch (const std::invalid_argument& e) {
        throw ConfigError(config.file, key + ".radius", e.what());
      }
    }
    if (model->fluid.model == FluidModel::kLsbt) {
      const LsbtDiscretizationCheck check = CheckLsbtDiscretization(rod.rest_positions, rod.radius);
      // The helix's connecting edge x1 → x2 (length R√2) is part of the paper's geometry.
      const int allowed = rc.shape == "helix" ? 1 : 0;
      if (check.edges_outside > allowed) {
        const int fits = rc.shape == "points" ? 0 : FittingLsbtNodes(rc, check.suggested_nodes, allowed);
        throw ConfigError(
            config.file, key + ".nodes",
            fmt::format("fluid.model = \"lsbt\" assumes edges of length 2δ = r0√e = {:.4g} m, "
                        "but {} edges differ by more than 5% (up to {:.0f}%); {}",
                        check.target_edge_length, check.edges_outside,
                        100.0 * check.max_relative_deviation,
                        fits > 0 ? fmt::format("nodes = {} fits", fits)
                                 : std::string("no node count fits this shape and radius (its "
                                               "edges cannot all be r0√e long)")));
      }
    }
  }
  if (model->coupling != FluidCoupling::kExplicit ||
      (model->fluid.model != FluidModel::kRss && model->fluid.model != FluidModel::kLsbt))
    return;
  const double limit = ExplicitStepLimit(*model);
  if (config.run.time_step > limit)
    throw ConfigError(config.file, "run.time_step",
                      fmt::format("fluid.coupling = \"explicit\" is stable only for a time step "
                                  "up to {:.3g} s (2 m/c for these masses and drag); got {:.3g} s. "
                                  "Use a smaller step or coupling = \"implicit\"",
                                  limit, config.run.time_step));
}

}  // namespace

double ExplicitStepLimit(const Model& model) {
  // The drag in the explicit step is forward Euler on M v̇ = −R v over the free nodes, with
  // R = (𝕄⁻¹)_ff: stable while |1 − h λ| ≤ 1 for every eigenvalue λ of M_f⁻¹ R, i.e.
  // h ≤ 2 Re λ / |λ|².
  const State rest = MakeRestState(model);
  std::vector<Matrix3X> positions;
  for (int r = 0; r < static_cast<int>(model.rods.size()); ++r)
    positions.push_back(RodPositions(model, r, rest.q));
  MatX mobility;
  AssembleMobility(model.fluid, MakeHydroRods(model, positions), &mobility);
  DenseLu<double> lu;
  // An exactly singular 𝕄 (no validated configuration gives one) sets no limit here: the explicit
  // drag then comes out not a number in the first step, which the Newton test reports
  // (HydroCoupling::Prepare).
  if (!lu.Compute(mobility)) return std::numeric_limits<double>::infinity();
  MatX resistance = MatX::Identity(mobility.rows(), mobility.cols());  // 𝕄⁻¹, column by column
  for (Eigen::Index j = 0; j < resistance.cols(); ++j) {
    VecX column = resistance.col(j);
    lu.Solve(&column);
    resistance.col(j) = column;
  }
  std::vector<Eigen::Index> free;
  VecX mass;
  std::vector<double> masses;
  for (const RodModel& rod : model.rods)
    for (int i = 0; i < rod.num_nodes(); ++i)
      for (int c = 0; c < 3; ++c)
        if (!std::binary_search(rod.fixed_dofs.begin(), rod.fixed_dofs.end(), NodeDof(i) + c)) {
          free.push_back(3 * (rod.node_offset + i) + c);
          masses.push_back(rod.mass(NodeDof(i) + c));
        }
  const Eigen::Index n = static_cast<Eigen::Index>(free.size());
  MatX a(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) a(i, j) = resistance(free[i], free[j]) / masses[i];
  const Eigen::VectorXcd lambda = Eigenvalues(a);
  double limit = std::numeric_limits<double>::infinity();
  for (const std::complex<double>& l : lambda)
    if (l.real() > 0.0) limit = std::min(limit, 2.0 * l.real() / std::norm(l));
  return limit;
}

namespace {

// A rod whose segments (beyond the self-contact exclusion) are closer than its diameter at rest.
void CheckSelfOverlap(const Config& config, const Model& model) {
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodConfig& rc = config.rods[r];
    const std::string key = fmt::format("rods.{}", r + 1);
    if (rc.shape == "helix" && rc.radius >= rc.helix_radius)
      throw ConfigError(config.file, key + ".radius",
                        fmt::format("rod {} overlaps itself: its radius {:.4g} m is not smaller "
                                    "than helix_radius {:.4g} m",
                                    r + 1, rc.radius, rc.helix_radius));
    Model alone;
    alone.rods = {model.rods[r]};
    alone.newton.contact_tolerance = 0.0;
    FinalizeLayout(&alone);
    const ContactSummary contacts = MeasureContacts(alone, MakeRestState(alone).q);
    if (contacts.detected > 0)
      throw ConfigError(config.file, key + (rc.shape == "helix" ? ".pitch" : ".points"),
                        fmt::format("rod {} overlaps itself at the start: two of its segments are "
                                    "{:.4g} m closer than its diameter {:.4g} m",
                                    r + 1, contacts.max_penetration, 2.0 * rc.radius));
  }
}

}  // namespace

void SetRodOmega(RodModel* rod, double omega) {
  // The imposed rotation vector is +ω ẑ: the first material frame turns about ẑ, i.e. about
  // its own tangent t⁰ at the rate ω (ẑ · t⁰) (t⁰ = −ẑ for the hanging helix: θ0 decreases).
  const Vec3 t0 = (rod->rest_positions.col(1) - rod->rest_positions.col(0)).normalized();
  rod->omega = omega;
  rod->twist_rate = omega * t0.z();
}

Model BuildModel(const Config& config) {
  Model model;
  model.fluid.model = ParseFluidModel(config.fluid.model);
  model.fluid.viscosity = config.fluid.viscosity;
  model.fluid.regularization = config.fluid.regularization;
  if (config.wall) model.fluid.wall = Wall{config.wall->point, config.wall->normal};
  model.coupling =
      config.fluid.coupling == "explicit" ? FluidCoupling::kExplicit : FluidCoupling::kImplicit;
  model.hydro.solver =
      config.fluid.solver == "direct" ? HydroSolver::kDirect : HydroSolver::kKrylov;
  model.hydro.krylov_tolerance = config.fluid.krylov_tolerance;
  model.hydro.rotate_preconditioner = config.fluid.krylov_rotate_preconditioner;
  model.hydro.coarse_rebuild_period = config.fluid.krylov_coarse_rebuild_period;
  model.hydro.mobility.tolerance = config.fluid.far_field_tolerance;
  model.hydro.mobility.fast_sum_tolerance = config.fluid.fast_sum_tolerance;
  // Cell bodies: the far-field sum in single precision (from 1e-4) is not linear to round-off, and
  // on a swimming cell (free body, two flagella, h = 20 ms) Newton stalls at 2.6× its tolerance
  // where the same sum in double converges (the 2-point rule of 1e-4 too); with bodies the sum
  // adds up in double, at most 1e-5 (docs/performance.md).
  if (!config.bodies.empty())
    model.hydro.mobility.fast_sum_tolerance = std::min(config.fluid.fast_sum_tolerance, 1e-5);
  // RSS only: LSBT's dense assembly costs less than the reuse's passes over 𝕄 (measured, N = 195:
  // 5.2 ms per step without, 5.7 ms with; docs/performance.md).
  model.hydro.mobility.reuse_tolerance =
      model.fluid.model == FluidModel::kRss ? config.fluid.mobility_reuse_tolerance : 0.0;
  model.integrator =
      config.run.integrator == "bdf2" ? TimeIntegrator::kBdf2 : TimeIntegrator::kEuler;
  model.contact = config.contact.enabled;
  model.gravity = config.gravity.acceleration;
  model.damping = config.solver.damping;
  model.newton.tolerance = config.solver.newton_tolerance;
  model.newton.max_iterations = config.solver.newton_max_iterations;
  model.newton.jacobian_max_age = config.solver.jacobian_max_age;
  model.newton.max_contact_rounds = config.contact.max_rounds;
  model.newton.contact_tolerance = config.contact.tolerance;

  for (const RodConfig& rc : config.rods) {
    RodModel rod;
    rod.radius = rc.radius;
    rod.density = rc.density;
    const double area = kPi * rc.radius * rc.radius;
    const double inertia = kPi * std::pow(rc.radius, 4) / 4.0;
    const double shear = rc.young_modulus / (2.0 * (1.0 + rc.poisson_ratio));
    rod.axial_stiffness = rc.young_modulus * area;
    rod.bending_stiffness = rc.young_modulus * inertia;
    rod.twisting_stiffness = shear * 2.0 * inertia;  // J = π r0⁴ / 2 = 2 I
    rod.rest_positions = RestShape(rc);
    CheckRestShape(config.file, fmt::format("rods.{}", model.rods.size() + 1), rc,
                   rod.rest_positions);
    rod.clamped_nodes = rc.clamped_nodes;
    rod.body = rc.body - 1;
    rod.axis_length = rc.axis_length;
    rod.helix_radius = rc.shape == "helix" ? rc.helix_radius : 0.0;
    // ω about +ẑ; omega_bar = ω μ l0⁴ / EI (SPEC).
    const double omega = rc.omega ? *rc.omega
                : rc.omega_bar ? *rc.omega_bar * rod.bending_stiffness /
                                     (config.fluid.viscosity * std::pow(rc.axis_length, 4))
                               : 0.0;
    for (const PointLoadConfig& l : rc.loads) rod.loads.push_back({l.node, l.force});
    FinalizeRod(&rod);
    SetRodOmega(&rod, omega);
    model.rods.push_back(std::move(rod));
  }
  AddBodies(config, &model);
  FinalizeLayout(&model);
  // "auto": the dense 𝕄 (3M × 3M) while it is small, the matrix-free operator above 500 nodes.
  // Measured (docs/performance.md, one thread, h = 1 ms): 2 helices (130 nodes) 2.1 ms dense
  // against 3.6 ms matrix-free, 4 helices (260) 7.2 against 10.7 ms, 10 helices (650) 58.9
  // against 52.6 ms with 3× less memory; above a wall (h = 10 ms) 10 helices 188 against 170 ms
  // with 5× less memory. With bodies "auto" stays dense (slower matrix-free: docs/performance.md).
  const bool matrix_free =
      config.fluid.mobility == "matrix_free" ||
      (config.fluid.mobility == "auto" && model.fluid.model == FluidModel::kRss &&
       model.num_nodes > 500 && config.fluid.solver != "direct" && config.bodies.empty());
  model.hydro.mobility.kind = matrix_free ? MobilityKind::kMatrixFree : MobilityKind::kDense;
  // The dense 𝕄 of the Krylov path is assembled to the far-field tolerance (fewer Gauss points
  // far away); the direct solver, the reference, keeps round-off.
  if (config.fluid.solver == "krylov") model.fluid.far_field_tolerance = config.fluid.far_field_tolerance;

  CheckFluidModel(config, &model);

  CheckSelfOverlap(config, model);
  CheckBodiesAndWall(config, model);
  // Rods overlapping at the start.
  std::vector<Eigen::AlignedBox3d> boxes;
  for (const RodModel& rod : model.rods) {
    Eigen::AlignedBox3d box;
    for (int i = 0; i < rod.num_nodes(); ++i) box.extend(Vec3(rod.rest_positions.col(i)));
    boxes.push_back(box);
  }
  for (std::size_t a = 0; a < model.rods.size(); ++a)
    for (std::size_t b = a + 1; b < model.rods.size(); ++b) {
      const double contact_distance = model.rods[a].radius + model.rods[b].radius;
      if (boxes[a].exteriorDistance(boxes[b]) >= contact_distance) continue;
      Model pair;
      pair.rods = {model.rods[a], model.rods[b]};
      FinalizeLayout(&pair);
      const double d = MinDistanceBetweenRods(pair, MakeRestState(pair).q);
      const double contact = model.rods[a].radius + model.rods[b].radius;
      if (d < contact)
        throw ConfigError(config.file, fmt::format("rods.{}.base", b + 1),
                          fmt::format("rod {} overlaps rod {} at the start: their center lines are "
                                      "{:.4g} m apart, less than r_a + r_b = {:.4g} m",
                                      b + 1, a + 1, d, contact));
    }
  return model;
}

namespace {

// The run in steps, checked: every count is a whole, representable number of steps ≥ 1.
void SetStepCounts(const Config& config, RunPlan* plan) {
  const double h = plan->time_step;
  const std::string duration_key = config.run.duration ? "run.duration" : "run.t_bar_end";
  const double steps = std::ceil(plan->duration / h - 1e-9);
  if (!(steps <= kMaxSteps))
    throw ConfigError(config.file, "run.time_step",
                      fmt::format("the run would take {:.3g} steps ({} gives {:.3g} s, "
                                  "run.time_step = {:.3g} s; at most {:.0e} steps)",
                                  plan->duration / h, duration_key, plan->duration, h, kMaxSteps));
  if (h > plan->duration * (1.0 + 1e-9))
    throw ConfigError(config.file, "run.time_step",
                      fmt::format("{:.6g} s is longer than the whole run ({:.6g} s)", h,
                                  plan->duration));
  auto check_interval = [&](const char* key, double interval, bool given) {
    if (h > interval * (1.0 + 1e-9))
      throw ConfigError(config.file, given ? key : "run.time_step",
                        fmt::format("{} = {:.6g} s is shorter than run.time_step = {:.6g} s", key,
                                    interval, h));
  };
  check_interval("run.output_interval", plan->output_interval, config.run.output_interval.has_value());
  check_interval("run.checkpoint_interval", plan->checkpoint_interval,
                 config.run.checkpoint_interval.has_value());
  plan->total_steps = std::max(1L, static_cast<long>(steps));
  plan->output_every = std::max(1L, std::lround(plan->output_interval / h));
  plan->checkpoint_every = std::max(1L, std::lround(plan->checkpoint_interval / h));
}

}  // namespace

RunPlan MakeRunPlan(const Config& config, const Model& model) {
  RunPlan plan;
  plan.name = config.run.name;
  plan.output_dir = config.run.output;
  plan.static_mode = config.run.mode == "static";
  plan.time_step = config.run.time_step;
  plan.frames = config.run.frames;
  plan.frames_format = config.run.frames_format == "binary"     ? VtkFormat::kBase64
                       : config.run.frames_format == "appended" ? VtkFormat::kAppended
                                                                : VtkFormat::kAscii;
  const Scales scales = CalcScales(model);
  plan.duration = config.run.duration ? *config.run.duration
                  : config.run.t_bar_end ? *config.run.t_bar_end * scales.time
                                         : 0.0;
  plan.output_interval = config.run.output_interval
                             ? *config.run.output_interval
                             : std::max(plan.time_step, plan.duration / 100.0);
  plan.checkpoint_interval = config.run.checkpoint_interval
                                 ? *config.run.checkpoint_interval
                                 : std::max(plan.time_step, plan.duration / 10.0);
  plan.checkpoint_wall_interval = config.run.checkpoint_wall_interval.value_or(0.0);
  plan.max_step_halvings = config.solver.max_step_halvings;
  if (config.run.stop_when_buckled)
    plan.stop_tip_axis_distance = kBuckledTipAxisDistanceOverR * config.rods[0].helix_radius;
  if (!plan.static_mode) SetStepCounts(config, &plan);
  return plan;
}

std::string DerivedJson(const Config& config, const Model& model) {
  const Scales scales = CalcScales(model);
  nlohmann::json d;
  d["time_scale"] = scales.time;
  d["force_scale"] = scales.force;
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodModel& rod = model.rods[r];
    const double l0 = rod.axis_length;
    d["EI"].push_back(rod.bending_stiffness);
    d["GJ"].push_back(rod.twisting_stiffness);
    d["EA"].push_back(rod.axial_stiffness);
    d["omega"].push_back(rod.omega);
    d["omega_bar"].push_back(rod.omega * config.fluid.viscosity * std::pow(l0, 4) /
                             rod.bending_stiffness);
    d["arc_length"].push_back(rod.rest_edge_length.sum());
    d["node_mass"].push_back(rod.mass(NodeDof(rod.num_nodes() / 2)));
    d["edge_length_min"].push_back(rod.rest_edge_length.minCoeff());
    d["edge_length_max"].push_back(rod.rest_edge_length.maxCoeff());
  }
  const RunPlan plan = MakeRunPlan(config, model);
  d["duration"] = plan.duration;
  d["t_bar_end"] = plan.duration / scales.time;
  d["output_interval"] = plan.output_interval;
  d["checkpoint_interval"] = plan.checkpoint_interval;
  d["steps"] = plan.total_steps;
  return d.dump(2);
}

}  // namespace stokesrods
