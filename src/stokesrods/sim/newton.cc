// Newton's method for one implicit step (sim/newton.h).
#include "stokesrods/sim/newton.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "stokesrods/sim/bodies.h"
#include "stokesrods/sim/clamp_border.h"

namespace stokesrods {

namespace {

// Weighted ∞-norm of a residual: the moment on θ^j is divided by |ē^j|, so that every entry is a
// force [N] and one tolerance serves both.
double ResidualNorm(const Model& model, const VecX& r) {
  double norm = 0.0;
  for (const RodModel& rod : model.rods)
    for (int k = 0; k < rod.num_dofs(); ++k) {
      const double w = (k % 4 == 3) ? 1.0 / rod.rest_edge_length(k / 4) : 1.0;
      norm = std::max(norm, w * std::abs(r(rod.dof_offset + k)));
    }
  return norm;
}

// The no-slip residual r_u [m/s] as a force: times the drag of a node's length of rod, 4πμ Λ_i
// (the order of a slender rod's resistance per unit length), ∞-norm [N].
double VelocityResidualNorm(const Model& model, const VecX& r_u) {
  double norm = 0.0;
  const double drag = 4.0 * kPi * model.fluid.viscosity;
  for (const RodModel& rod : model.rods)
    for (int i = 0; i < rod.num_nodes(); ++i)
      norm = std::max(norm, drag * rod.rest_voronoi_length(i) *
                                r_u.segment<3>(3 * (rod.node_offset + i)).cwiseAbs().maxCoeff());
  for (const BodyModel& body : model.bodies)  // a surface point: the drag of its blob, 4πμ ε
    for (int j = 0; j < body.num_points(); ++j)
      norm = std::max(norm, drag * body.regularization *
                                r_u.segment<3>(3 * (model.num_nodes + body.point_offset + j))
                                    .cwiseAbs().maxCoeff());
  for (const BodyModel& body : model.bodies) {  // a free body's balance: force, torque / radius
    if (body.free_index < 0) continue;
    const Vec6 r = r_u.segment<6>(3 * model.num_hydro_points() + 6 * body.free_index);
    norm = std::max({norm, r.head<3>().cwiseAbs().maxCoeff(),
                     r.tail<3>().cwiseAbs().maxCoeff() / body.radius});
  }
  return norm;
}

// The residual that round-off alone leaves: a position known to ε|x| changes a stretching force
// by EA ε |x| / |ē|; a few ulps of that summed over a node's stencils [N].
double RoundOffFloor(const Model& model, const VecX& q) {
  double floor = 0.0;
  for (const RodModel& rod : model.rods) {
    const double extent = q.segment(rod.dof_offset, rod.num_dofs()).cwiseAbs().maxCoeff();
    floor = std::max(floor, 16.0 * std::numeric_limits<double>::epsilon() * rod.axial_stiffness *
                                extent / rod.rest_edge_length.minCoeff());
  }
  return floor;
}

// Σ over the DOFs of (w d_i)², w = 1 on positions and |ē^j| on twist angles, of the difference
// d_i = delta(i): CorrectionNorm's and CorrectionDistance's one loop.
template <class Difference>
double WeightedNorm(const Model& model, const Difference& delta) {
  double sum = 0.0;
  for (const RodModel& rod : model.rods)
    for (int k = 0; k < rod.num_dofs(); ++k) {
      const double w = (k % 4 == 3) ? rod.rest_edge_length(k / 4) : 1.0;
      sum += std::pow(w * delta(rod.dof_offset + k), 2);
    }
  return std::sqrt(sum);
}

}  // namespace

double CorrectionNorm(const Model& model, const VecX& delta) {
  return WeightedNorm(model, [&](int i) { return delta(i); });
}

double CorrectionDistance(const Model& model, const VecX& a, const VecX& b) {
  return WeightedNorm(model, [&](int i) { return a(i) - b(i); });
}

std::string DescribeResidual(const Model& model, const VecX& r) {
  std::size_t worst_rod = 0;
  int worst_dof = 0;
  double worst = -1.0;
  for (std::size_t i = 0; i < model.rods.size() && std::isfinite(worst); ++i) {
    const RodModel& rod = model.rods[i];
    for (int k = 0; k < rod.num_dofs(); ++k) {
      const double w = (k % 4 == 3) ? 1.0 / rod.rest_edge_length(k / 4) : 1.0;
      const double v = w * std::abs(r(rod.dof_offset + k));
      if (v > worst || !std::isfinite(v)) worst = v, worst_rod = i, worst_dof = k;
      if (!std::isfinite(v)) break;
    }
  }
  const bool twist = worst_dof % 4 == 3;
  return fmt::format("{} at rod {}, {} {} ({})",
                     std::isfinite(worst) ? "largest" : "not a number or infinite", worst_rod + 1,
                     twist ? "edge" : "node", worst_dof / 4, twist ? "a twist moment" : "a force");
}

// How the iterations went, when that points to a remedy: most of them damped by the line search
// (the Newton matrix nearly singular: the step is close to an instability and too long for it),
// and the last ones converging fast (more iterations would likely have finished the solve).
std::string DescribeConvergence(const Model& model, const NewtonReport& newton) {
  std::string text;
  if (2 * newton.damped_iterations >= newton.iterations && newton.iterations > 0)
    text += fmt::format("; {} of the {} iterations were damped by the line search (a nearly "
                        "singular Newton matrix: the step is too long near an instability)",
                        newton.damped_iterations, newton.iterations);
  if (newton.last_reduction < 0.5 && std::isfinite(newton.residual))
    text += fmt::format("; the last iteration reduced the residual {:.3g} times (still converging: "
                        "a larger solver.newton_max_iterations than {} may finish it)",
                        1.0 / newton.last_reduction, model.newton.max_iterations);
  return text;
}

bool UsesSaddle(const Model& model, double h, const Workspace& ws) {
  return h > 0.0 && ws.nonlocal_fluid && model.coupling == FluidCoupling::kImplicit;
}

bool FactorizeJacobian(const Model& model, double h, Workspace* ws) {
  if (UsesSaddle(model, h, *ws))
    return ws->hydro.FactorizeNewtonSystem(model, h, &ws->jacobian,
                                           ws->free_clamps ? &ws->clamp_borders : nullptr);
  for (BandedMatrix& b : ws->jacobian)
    if (!b.Factorize()) return false;
  return true;
}

int NewtonCorrection(const Model& model, double h, const VecX& residual, const VecX& r_u,
                     Workspace* ws, VecX* dq, VecX* df, VecX* du, double velocity_tolerance) {
  if (UsesSaddle(model, h, *ws)) {
    const HydroSolveReport report = ws->hydro.SolveNewtonSystem(
        model, ws->jacobian, h, residual, r_u, dq, df, du, velocity_tolerance);
    return report.krylov_iterations;
  }
  *dq = -residual;
  SolveRodsBanded(model, ws->jacobian, dq);
  return 0;
}

// Newton's method from the iterate in ws->q, globalized by Deuflhard's natural monotonicity test:
// a step α δ is accepted when the simplified correction −J⁻¹ r(q + α δ), with the same factors,
// is smaller than (1 − α/4) |δ|. Unlike a test on |r|, this is affine invariant, so the stiff
// stretching modes (EA ≫ EI/L²) do not stall it. Converged when the residual is below the
// tolerance, or when the next correction is below 1e-10 of the rod length (conditioning allows
// no better). The factorized Newton matrix is kept across iterations and steps (modified Newton)
// while it contracts well: rebuilt when it is older than jacobian_max_age steps, when h changed,
// or when one iteration reduces the correction by less than a factor 4.
NewtonReport SolveNewton(const Model& model, const State& start, double h, Workspace* ws) {
  NewtonReport report;
  const bool saddle = UsesSaddle(model, h, *ws);
  const double step_tolerance = 1e-10 * model.length_scale;
  // Old factors are worth keeping while they converge a step in a few iterations; a step that
  // needed more (a rod turning fast, a contact) rebuilds them at the start of the next.
  // In time steps kept only after a clean step (one full Newton step that met the tolerance): a
  // step that needed more was too far from its guess for old factors to take it in one.
  // And not while a step that kept them has lately failed to be clean: after each such step the
  // next reuse waits twice as many steps as after the one before (1, 2, 4 … 64; a clean step
  // with kept factors clears it). On paper Fig. 1 at h = 10 ms with jacobian_max_age = 5, kept
  // factors left most steps unclean: 1.63 Newton iterations per step, 1.23 with the back-off,
  // 1.11 with fresh factors at every step; at 1 ms every step stays clean.
  const bool last_poor = h > 0.0 ? !ws->last_clean : ws->last_iterations > 3;
  const bool waiting = h > 0.0 && ws->reuse_wait > 0;
  if (waiting) --ws->reuse_wait;
  bool fresh = !ws->factors_valid || ws->factors_h != h ||
               ws->factors_age >= model.newton.jacobian_max_age || last_poor || waiting ||
               (saddle && ws->hydro.wants_refresh());
  const bool kept = !fresh && h > 0.0;
  const auto judge_reuse = [&](bool clean) {
    if (!kept) return;
    ws->reuse_backoff = clean ? 0 : std::min(64, std::max(1, 2 * ws->reuse_backoff));
    ws->reuse_wait = ws->reuse_backoff;
  };
  Evaluate(model, start, h, ws->q, ws->hydro_force, fresh, ws, &ws->frames, &ws->residual);
  if (fresh) ws->factors_valid = false;  // ws->jacobian now holds an unfactorized assembly
  // r_u; the free bodies' rows take the loads of their clamps (of the Evaluate just before).
  auto no_slip_residual = [&](const VecX& q, const VecX& f, VecX* r_u) {
    ws->hydro.VelocityResidual(model, q, start.q, h, f, r_u);
    if (ws->free_clamps) r_u->tail(ws->clamp_loads.size()) -= ws->clamp_loads;
    if (model.num_free_bodies > 0) r_u->tail(ws->body_load.size()) += ws->body_load;
  };
  if (saddle) no_slip_residual(ws->q, ws->hydro_force, &ws->velocity_residual);
  auto norm_of = [&](const VecX& r, const VecX& r_u) {
    return saddle ? std::max(ResidualNorm(model, r), VelocityResidualNorm(model, r_u))
                  : ResidualNorm(model, r);
  };
  // The force scale: the characteristic bending force or the applied forces (ws->force of the
  // last Evaluate), if larger; never below the round-off floor of the stretching forces at q.
  auto tolerance_at = [&](const VecX& q) {
    const double scale = std::max(model.force_scale, ResidualNorm(model, ws->force));
    return std::max(model.newton.tolerance * scale, RoundOffFloor(model, q));
  };
  bool have_jacobian = fresh;
  bool have_correction = false;  // ws->delta already holds the correction at ws->q
  double norm = norm_of(ws->residual, ws->velocity_residual);
  bool small_correction = false;
  bool simplified_solved = false;  // a simplified correction was needed
  for (report.iterations = 0;; ++report.iterations) {
    report.tolerance = tolerance_at(ws->q);
    report.residual = norm;
    if (norm <= report.tolerance || small_correction) {
      report.converged = true;
      ws->last_iterations = report.iterations;
      ws->last_clean = report.iterations <= 1 && !simplified_solved;
      judge_reuse(ws->last_clean);
      return report;
    }
    if (report.iterations == model.newton.max_iterations) {
      judge_reuse(false);
      return report;
    }
    // The no-slip residual a Krylov solve may leave: a tenth of the tolerance, as a velocity
    // through the largest node drag 4πμΛ (VelocityResidualNorm).
    const double velocity_tolerance =
        0.1 * report.tolerance / (4.0 * kPi * model.fluid.viscosity * model.max_voronoi_length);
    if (fresh) {
      if (!have_jacobian)
        Evaluate(model, start, h, ws->q, ws->hydro_force, true, ws, &ws->frames, &ws->residual);
      ws->factors_valid = FactorizeJacobian(model, h, ws);
      ws->factors_h = h;
      ws->factors_age = 0;
      if (!ws->factors_valid) return report;
      have_correction = false;
    }
    if (!have_correction)
      report.krylov_iterations += NewtonCorrection(model, h, ws->residual, ws->velocity_residual,
                                                   ws, &ws->delta, &ws->hydro_delta,
                                                   &ws->hydro_rate, velocity_tolerance);
    const double delta_norm = CorrectionNorm(model, ws->delta);
    double alpha = 1.0, simplified_norm = 0.0;
    for (int halving = 0;; ++halving, alpha *= 0.5) {
      ws->q_try = ws->q + alpha * ws->delta;
      if (saddle) {
        ws->hydro_force_try = ws->hydro_force + alpha * ws->hydro_delta;
        ws->velocity_residual_try = ws->velocity_residual + alpha * ws->hydro_rate;
      }
      // Clamps on free bodies: placed exactly by the trial's V (Φ, not its linearization); r_u
      // is then evaluated, not extrapolated (the clamps' reactions are nonlinear in q).
      if (saddle && ws->free_clamps)
        PlaceFreeClamps(model, ws->body_step, ws->hydro_force_try, &ws->q_try);
      Evaluate(model, start, h, ws->q_try, saddle ? ws->hydro_force_try : ws->hydro_force, false,
               ws, &ws->frames_try, &ws->residual_try);
      if (saddle && ws->free_clamps)
        no_slip_residual(ws->q_try, ws->hydro_force_try, &ws->velocity_residual_try);
      // A full step that already meets the tolerance is accepted without its simplified
      // correction (one linear solve less at the end of each step).
      if (alpha == 1.0 &&
          norm_of(ws->residual_try, ws->velocity_residual_try) <= tolerance_at(ws->q_try)) {
        simplified_norm = 0.0;
        ws->simplified.setZero();
        if (saddle) ws->simplified_hydro_delta.setZero(), ws->simplified_hydro_rate.setZero();
        break;
      }
      simplified_solved = true;
      report.krylov_iterations += NewtonCorrection(
          model, h, ws->residual_try, ws->velocity_residual_try, ws, &ws->simplified,
          &ws->simplified_hydro_delta, &ws->simplified_hydro_rate, velocity_tolerance);
      simplified_norm = CorrectionNorm(model, ws->simplified);
      if (simplified_norm <= (1.0 - 0.25 * alpha) * delta_norm || halving == 10) break;
    }
    std::swap(ws->q, ws->q_try);
    std::swap(ws->frames, ws->frames_try);
    std::swap(ws->residual, ws->residual_try);
    if (saddle) {
      std::swap(ws->hydro_force, ws->hydro_force_try);
      std::swap(ws->velocity_residual, ws->velocity_residual_try);
    }
    const double previous_norm = norm;
    norm = norm_of(ws->residual, ws->velocity_residual);
    report.last_reduction = norm / previous_norm;
    if (alpha < 1.0) ++report.damped_iterations;
    small_correction = simplified_norm <= step_tolerance;
    // Poor contraction (or a damped step): rebuild the factors at the new iterate. Otherwise the
    // simplified correction, made with the same factors at the accepted iterate, is the next one.
    have_jacobian = false;
    fresh = simplified_norm > 0.25 * delta_norm || alpha < 1.0;
    std::swap(ws->delta, ws->simplified);
    std::swap(ws->hydro_delta, ws->simplified_hydro_delta);
    std::swap(ws->hydro_rate, ws->simplified_hydro_rate);
    have_correction = true;
  }
}

}  // namespace stokesrods
