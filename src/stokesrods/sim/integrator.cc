#include "stokesrods/sim/integrator.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "stokesrods/sim/elastic_assembly.h"

namespace stokesrods {

Workspace::Workspace(const Model& model) : local_forces(MakeLocalForces(model)) {
  nonlocal_fluid =
      model.fluid.model == FluidModel::kRss || model.fluid.model == FluidModel::kLsbt;
  const int n = model.num_dofs;
  q = q_try = force = residual = residual_try = delta = contact_force = VecX::Zero(n);
  for (const RodModel& rod : model.rods) jacobian.emplace_back(rod.num_dofs(), 10);
}

void DriveBoundaryConditions(const Model& model, double h, VecX* q) {
  for (const RodModel& rod : model.rods)
    if (rod.clamped_nodes >= 2) (*q)(rod.dof_offset + TwistDof(0)) += h * rod.twist_rate;
}

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

// r(q) and, when `with_jacobian`, the per-rod banded Jacobians ∂r/∂q in ws->jacobian.
// h = 0 is the static problem (no inertia, no velocity-dependent forces).
void Evaluate(const Model& model, const State& start, double h, const VecX& q, bool with_jacobian,
              Workspace* ws, std::vector<RodFrames>* frames, VecX* residual) {
  TransportFrames(model, q, start.rods, frames);
  ws->force.setZero();
  std::vector<BandedMatrix>* jac = with_jacobian ? &ws->jacobian : nullptr;
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    if (jac) (*jac)[r].SetZero();
    AddElasticForces(model.rods[r], q, (*frames)[r], &ws->force, jac ? &(*jac)[r] : nullptr);
  }
  const StepContext ctx{&start.q, h, ws->load_factor};
  for (const auto& f : ws->local_forces) f->AddTo(model, ctx, q, &ws->force, jac);
  if (h > 0.0 && ws->nonlocal_fluid) ws->hydro.AddTo(model, ctx, q, &ws->force);
  if (h > 0.0) ws->force += ws->contact_force;

  *residual = -ws->force;
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodModel& rod = model.rods[r];
    const int o = rod.dof_offset, n = rod.num_dofs();
    if (h > 0.0) {
      residual->segment(o, n) += rod.mass.cwiseProduct(q.segment(o, n) - start.q.segment(o, n) -
                                                       h * start.velocity.segment(o, n)) / (h * h);
      if (jac) for (int k = 0; k < n; ++k) (*jac)[r](k, k) += rod.mass(k) / (h * h);
    }
    for (int k : rod.fixed_dofs) {
      (*residual)(o + k) = 0.0;
      if (jac) (*jac)[r].FixDof(k);
    }
  }
}

// δ = −J⁻¹ r.
bool SolveLinear(const Model& model, double h, const VecX& residual, Workspace* ws) {
  ws->delta = -residual;
  if (h > 0.0 && ws->nonlocal_fluid && model.coupling == FluidCoupling::kImplicit)
    return ws->hydro.SolveNewtonSystem(model, h, &ws->jacobian, &ws->delta);
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    if (!ws->jacobian[r].Factorize()) return false;
    ws->jacobian[r].Solve(ws->delta.data() + model.rods[r].dof_offset, 1);
  }
  return true;
}

// Newton's method with a backtracking line search on |r|, from the iterate in ws->q.
NewtonReport SolveNewton(const Model& model, const State& start, double h, Workspace* ws) {
  NewtonReport report;
  Evaluate(model, start, h, ws->q, true, ws, &ws->frames, &ws->residual);
  double norm = ResidualNorm(model, ws->residual);
  for (report.iterations = 0; report.iterations < model.newton.max_iterations;
       ++report.iterations) {
    // The force scale: the characteristic bending force or the applied forces, if larger.
    const double scale = std::max(model.force_scale, ResidualNorm(model, ws->force));
    report.tolerance = model.newton.tolerance * scale;
    report.residual = norm;
    if (norm <= report.tolerance) {
      report.converged = true;
      return report;
    }
    if (report.iterations > 0) Evaluate(model, start, h, ws->q, true, ws, &ws->frames, &ws->residual);
    if (!SolveLinear(model, h, ws->residual, ws)) return report;
    const double norm2 = ws->residual.squaredNorm();
    double alpha = 1.0;
    for (int halving = 0; halving < 8; ++halving, alpha *= 0.5) {
      ws->q_try = ws->q + alpha * ws->delta;
      Evaluate(model, start, h, ws->q_try, false, ws, &ws->frames_try, &ws->residual_try);
      if (ws->residual_try.squaredNorm() <= (1.0 - 1e-4 * alpha) * norm2) break;
    }
    std::swap(ws->q, ws->q_try);
    std::swap(ws->frames, ws->frames_try);
    std::swap(ws->residual, ws->residual_try);
    norm = ResidualNorm(model, ws->residual);
  }
  report.residual = norm;
  report.converged = norm <= report.tolerance;
  return report;
}

}  // namespace

StepReport Step(const Model& model, double h, State* state, Workspace* ws) {
  StepReport report;
  for (const auto& f : ws->local_forces) f->Prepare(model, state->q);
  if (ws->nonlocal_fluid) ws->hydro.Prepare(model, state->q, state->velocity);
  ws->contact_force.setZero();
  ws->load_factor = 1.0;

  for (report.contact_rounds = 1;; ++report.contact_rounds) {
    ws->q = state->q + h * state->velocity;  // Algorithm 1's guess
    for (const RodModel& rod : model.rods)
      for (int k : rod.fixed_dofs) ws->q(rod.dof_offset + k) = state->q(rod.dof_offset + k);
    DriveBoundaryConditions(model, h, &ws->q);
    const NewtonReport newton = SolveNewton(model, *state, h, ws);
    report.newton_iterations += newton.iterations;
    if (!newton.converged) {
      report.message = fmt::format(
          "Newton did not converge at t = {:.6g} s: residual {:.3e} N > tolerance {:.3e} N after "
          "{} iterations",
          state->time + h, newton.residual, newton.tolerance, newton.iterations);
      return report;
    }
    if (!model.contact) break;
    report.contact = AddContactForces(model, ws->q, h, &ws->contact_force);
    if (report.contact.active == 0) break;
    report.contact_pairs = std::max(report.contact_pairs, report.contact.detected);
    if (report.contact_rounds >= model.newton.max_contact_rounds) {
      report.message = fmt::format(
          "contact not resolved at t = {:.6g} s: {} pairs still closer than the contact distance "
          "after {} rounds (largest penetration {:.3e} m)",
          state->time + h, report.contact.active, report.contact_rounds,
          report.contact.max_penetration);
      return report;
    }
  }
  if (model.contact) report.contact = MeasureContacts(model, ws->q);

  state->velocity = (ws->q - state->q) / h;
  state->q = ws->q;
  std::swap(state->rods, ws->frames);
  ws->frames = state->rods;
  state->time += h;
  ++state->step;
  report.ok = true;
  return report;
}

StepReport SolveStatic(const Model& model, State* state, Workspace* ws) {
  StepReport report;
  ws->contact_force.setZero();
  double reached = 0.0, increment = 1.0;
  while (reached < 1.0) {
    ws->load_factor = std::min(1.0, reached + increment);
    ws->q = state->q;
    const NewtonReport newton = SolveNewton(model, *state, 0.0, ws);
    report.newton_iterations += newton.iterations;
    if (newton.converged) {
      reached = ws->load_factor;
      state->q = ws->q;
      std::swap(state->rods, ws->frames);
      ws->frames = state->rods;
      increment = std::min(2.0 * increment, 1.0);
      continue;
    }
    increment *= 0.5;
    if (increment < 1e-4) {
      report.message = fmt::format(
          "static solve did not converge: load factor {:.4g} reached, Newton residual {:.3e} N > "
          "{:.3e} N even with a load increment of {:.1e}",
          reached, newton.residual, newton.tolerance, increment * 2.0);
      return report;
    }
  }
  state->velocity.setZero();
  if (model.contact) report.contact = MeasureContacts(model, state->q);
  report.ok = true;
  return report;
}

ClampLoad CalcClampLoad(const Model& model, const State& state, const Workspace& ws, int r) {
  const RodModel& rod = model.rods[r];
  ClampLoad load;
  const int o = rod.dof_offset;
  const Vec3 origin = state.q.segment<3>(o + NodeDof(0));
  for (int i = 0; i < rod.clamped_nodes; ++i) {
    const Vec3 f = ws.force.segment<3>(o + NodeDof(i));
    load.force += f;
    load.torque_z += (state.q.segment<3>(o + NodeDof(i)) - origin).cross(f).z();
  }
  if (rod.clamped_nodes >= 2) {  // the moment on θ0 acts about the first tangent
    const Vec3 t0 = state.rods[r].tangents[0];
    load.torque_z += ws.force(o + TwistDof(0)) * t0.z();
  }
  return load;
}

}  // namespace stokesrods
