#include "stokesrods/sim/integrator.h"

#include <algorithm>

#include <fmt/format.h>

#include "stokesrods/common/parallel.h"
#include "stokesrods/sim/bodies.h"
#include "stokesrods/sim/clamp_border.h"
#include "stokesrods/sim/elastic_assembly.h"
#include "stokesrods/sim/newton.h"

namespace stokesrods {

Workspace::Workspace(const Model& model) : local_forces(MakeLocalForces(model)) {
  nonlocal_fluid = IsNonlocal(model.fluid.model);
  const int n = model.num_dofs;
  q = q_try = force = residual = residual_try = delta = simplified = contact_force = VecX::Zero(n);
  for (const RodModel& rod : model.rods) jacobian.emplace_back(rod.num_dofs(), 10);
  if (nonlocal_fluid) {
    hydro.Init(model);
    hydro_force = hydro_force_try = VecX::Zero(model.hydro_size());
    free_clamps = HasFreeClamps(model);
  }
}

StepHistory CaptureHistory(const Workspace& ws) {
  return {ws.previous_q,
          ws.previous_velocity,
          ws.previous_h,
          ws.older_velocity,
          ws.older_h,
          ws.cubic_predictor,
          ws.damped_miss,
          ws.nonlocal_fluid ? ws.hydro_force : VecX(),
          ws.earlier_drags,
          ws.previous_poses,
          ws.nonlocal_fluid ? ws.hydro.mobility_reuse_history() : MobilityReuseHistory{}};
}

void RestoreHistory(const StepHistory& history, Workspace* ws) {
  ws->previous_q = history.previous_q;
  ws->previous_velocity = history.previous_velocity;
  ws->previous_h = history.previous_h;
  ws->older_velocity = history.older_velocity;
  ws->older_h = history.older_h;
  ws->cubic_predictor = history.cubic_predictor;
  ws->damped_miss = history.damped_miss;
  ws->previous_poses = history.previous_poses;
  if (ws->nonlocal_fluid) ws->hydro_force = history.hydro_force;
  ws->earlier_drags = history.earlier_drags;
  ForgetReuse(ws);
  if (ws->nonlocal_fluid) ws->hydro.RestoreMobilityReuse(history.mobility_reuse);
}

void ForgetReuse(Workspace* ws) {
  ws->factors_valid = false;
  ws->factors_h = -1.0;
  ws->factors_age = 0;
  ws->last_iterations = 0;
  ws->last_clean = false;
  ws->reuse_wait = ws->reuse_backoff = 0;
  if (ws->nonlocal_fluid) ws->hydro.ForgetReuse(ws->hydro_force);
}

void DriveBoundaryConditions(const Model& model, double h, VecX* q) {
  for (const RodModel& rod : model.rods)
    if (rod.clamped_nodes >= 2) (*q)(rod.dof_offset + TwistDof(0)) += h * rod.twist_rate;
}

void ExtrapolateEdgeLengths(const Model& model, const VecX& q_start, const VecX* q_before,
                            VecX* lengths) {
  lengths->resize(model.num_nodes);
  for (const RodModel& rod : model.rods)
    for (int i = 0; i + 1 < rod.num_nodes(); ++i) {
      const int a = rod.dof_offset + NodeDof(i), b = rod.dof_offset + NodeDof(i + 1);
      double length = (q_start.segment<3>(b) - q_start.segment<3>(a)).norm();
      if (q_before)
        length += length - (q_before->segment<3>(b) - q_before->segment<3>(a)).norm();
      (*lengths)(rod.node_offset + i) = length;
    }
}

void SetEdgeLengths(const Model& model, const VecX& lengths, VecX* q) {
  for (const RodModel& rod : model.rods) {
    if (rod.body >= 0) continue;  // its first nodes go where its body puts them
    auto fixed = rod.fixed_dofs.begin();  // sorted
    for (int i = 0; i + 1 < rod.num_nodes(); ++i) {
      while (fixed != rod.fixed_dofs.end() && *fixed < NodeDof(i + 1)) ++fixed;
      if (fixed != rod.fixed_dofs.end() && *fixed == NodeDof(i + 1))
        continue;  // a fixed node stays where the step drives it
      const int a = rod.dof_offset + NodeDof(i), b = rod.dof_offset + NodeDof(i + 1);
      const Vec3 edge = q->segment<3>(b) - q->segment<3>(a);
      const double guessed = edge.norm();
      if (guessed > 0.0)
        q->segment<3>(b) = q->segment<3>(a) + (lengths(rod.node_offset + i) / guessed) * edge;
    }
  }
}

void Evaluate(const Model& model, const State& start, double h, const VecX& q,
              const VecX& hydro_force, bool with_jacobian, Workspace* ws,
              std::vector<RodFrames>* frames, VecX* residual) {
  TransportFrames(model, q, start.rods, frames);
  ws->force.setZero();
  std::vector<BandedMatrix>* jac = with_jacobian ? &ws->jacobian : nullptr;
  // Rods in parallel: each writes only its own DOFs of the force and its own banded matrix.
  const int num_rods = static_cast<int>(model.rods.size());
  ForEachDynamic(num_rods, RodsInParallel(num_rods, model.num_nodes), [&](int r) {
    if (jac) (*jac)[static_cast<size_t>(r)].SetZero();
    AddElasticForces(model.rods[static_cast<size_t>(r)], q, (*frames)[static_cast<size_t>(r)],
                     &ws->force, jac ? &(*jac)[static_cast<size_t>(r)] : nullptr);
  });
  const StepContext ctx{&start.q, h, ws->load_factor};
  for (const auto& f : ws->local_forces) f->AddTo(model, ctx, q, &ws->force, jac);
  if (h > 0.0 && ws->nonlocal_fluid) HydroCoupling::AddNodalForce(model, hydro_force, &ws->force);
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
  }
  // Clamps on free bodies: their reactions load the bodies, their rows and columns of B border
  // the Newton system (sim/clamp_border.h); both before the clamped entries are fixed.
  if (h > 0.0 && ws->free_clamps) {
    if (jac) CaptureClampBorders(model, ws->body_step.geometry, q, *jac, &ws->clamp_borders);
    ClampLoads(model, ws->body_step.geometry, q, *residual, &ws->clamp_loads);
  }
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodModel& rod = model.rods[r];
    const int o = rod.dof_offset;
    for (int k : rod.fixed_dofs) {
      (*residual)(o + k) = 0.0;
      if (jac) (*jac)[r].FixDof(k);
    }
  }
}

namespace {

// The implicit drag's first guess for a step of size h: ws->hydro_force, the drag f_k at t_k,
// extrapolated through the drags of the steps before (ws->earlier_drags) when they had the same
// size, quadratically (3f_k − 3f_{k−1} + f_{k−2}) once two are known, as the predictor extrapolates
// q. Only a guess (Newton solves for f), but a closer one leaves GMRES less to do: on the
// paper's Fig. 1 at h = 1 ms it takes 2.1 products per step instead of 3.1, on ten flagella 4.4
// instead of 6.0. f_k is kept in ws->drag_at_start.
void PredictDrag(double h, Workspace* ws) {
  VecX& f = ws->hydro_force;
  ws->drag_at_start = f;
  ws->drag_extrapolated = false;
  if (ws->previous_h != h || !ws->extrapolate_drag) return;
  const VecX& f1 = ws->earlier_drags[0];
  const VecX& f2 = ws->earlier_drags[1];
  if (f1.size() != f.size()) return;
  ws->drag_extrapolated = true;
  if (f2.size() == f.size())
    f += 2.0 * f - 3.0 * f1 + f2;
  else
    f += f - f1;
}

// After a step of size h: f_k joins the earlier drags (the older ones only if of the same size).
void RememberDrag(double h, Workspace* ws) {
  if (ws->previous_h == h)
    std::swap(ws->earlier_drags[1], ws->earlier_drags[0]);
  else
    ws->earlier_drags[1].resize(0);
  std::swap(ws->earlier_drags[0], ws->drag_at_start);
}

}  // namespace

void PrepareStep(const Model& model, const State& start, Workspace* ws) {
  for (const auto& f : ws->local_forces) f->Prepare(model, start.q);
  if (ws->nonlocal_fluid) {
    if (!model.bodies.empty()) ws->hydro.SetBodies(model, start.bodies);
    ws->hydro.Prepare(model, start.q, start.velocity);
    if (model.coupling == FluidCoupling::kExplicit) ws->hydro_force = ws->hydro.explicit_force();
  }
  ws->contact_force.setZero();
  ws->body_load.setZero(6 * model.num_free_bodies);  // the bodies' own loads, then contacts'
  for (const BodyModel& body : model.bodies)
    if (body.free_index >= 0) ws->body_load.segment<6>(6 * body.free_index) << body.force, body.torque;
  ws->load_factor = 1.0;
}

namespace {

StepReport StepOnce(const Model& model, double h, State* state, Workspace* ws);

}  // namespace

// A step whose extrapolated drag guess did not converge is tried once more from the drag f_k
// itself, before the caller halves it: at large steps (BDF2 at 100 ms on the swimming cell) the
// extrapolation can start Newton where it fails, and the plain guess does not.
// Likewise a step whose Newton started from the cubic predictor is tried again from the damped
// one (Predict), and the next steps start from the damped one until it misses by more.
StepReport Step(const Model& model, double h, State* state, Workspace* ws) {
  StepReport report = StepOnce(model, h, state, ws);
  if (report.ok || (!ws->drag_extrapolated && !ws->used_cubic)) return report;
  ws->cubic_predictor = false;  // the retry starts from the damped guess
  ws->extrapolate_drag = false;
  StepReport retry = StepOnce(model, h, state, ws);
  ws->extrapolate_drag = true;
  retry.newton_iterations += report.newton_iterations;
  retry.krylov_iterations += report.krylov_iterations;
  return retry;
}

namespace {

// The step's two guesses of q(t_{k+1}) (Workspace::damped_guess, cubic_guess), with the fixed and
// driven DOFs where the step puts them, and the one its Newton starts from in ws->q.
//  - Damped: Algorithm 1's guess q_k + h q̇_k, plus ½h² q̈_k = ½h (q̇_k − q̇_{k−1}) once two
//    velocities are known (rods that turn by a sizeable angle per step move on circles, which the
//    linear guess misses). Robust at large steps, where the velocities of the stiff modes
//    alternate from step to step; BDF2 takes its mobility and local drag there.
//  - Cubic: q_k + h q̇_{k+1} with q̇_{k+1} = 3q̇_k − 3q̇_{k−1} + q̇_{k−2} (the velocities of three
//    steps of the same h extrapolated quadratically; with implicit Euler's q̇ = Δq/h, the cubic
//    through q_{k−3} … q_k). Where the motion is smooth it is far closer: on paper Fig. 1 the
//    first Newton correction 2.6e-7 → 1.2e-10 m at h = 1 ms, and at 10 ms (with the edges'
//    lengths set, StepOnce) Newton 3.0 → 1.1 iterations and GMRES 7.0 → 3.0 products per step.
//    For implicit Euler only: BDF2's q̇ is not Δq/h, and at its 20 and 40 ms steps the same
//    extrapolation is farther and Newton takes twice the iterations or fails (docs/
//    performance.md, sessions 32 and 33).
// Newton starts from the cubic one where it came closer to the last step's solution than the
// damped one (Workspace::cubic_predictor, set in StepOnce after each step), unless the two now
// differ by more than four times the damped one's last miss (the motion changed: a contact, a
// drive that starts); a step that fails from it is tried again from the damped one (Step).
void Predict(const Model& model, double h, const State& state, Workspace* ws) {
  const auto place = [&](VecX* q) {
    for (const RodModel& rod : model.rods)
      for (int k : rod.fixed_dofs) (*q)(rod.dof_offset + k) = state.q(rod.dof_offset + k);
    DriveBoundaryConditions(model, h, q);
  };
  const auto n = state.velocity.size();
  const bool have_previous = ws->previous_velocity.size() == n;
  ws->damped_guess = state.q + h * state.velocity;
  if (have_previous) ws->damped_guess += 0.5 * h * (state.velocity - ws->previous_velocity);
  place(&ws->damped_guess);
  ws->have_cubic_guess = model.integrator == TimeIntegrator::kEuler && have_previous &&
      ws->older_velocity.size() == n && ws->previous_h == h && ws->older_h == h;
  if (ws->have_cubic_guess) {
    ws->cubic_guess =
        state.q + h * (3.0 * state.velocity - 3.0 * ws->previous_velocity + ws->older_velocity);
    place(&ws->cubic_guess);
  }
  ws->used_cubic =
      ws->cubic_predictor && ws->have_cubic_guess &&
      CorrectionDistance(model, ws->cubic_guess, ws->damped_guess) <= 4.0 * ws->damped_miss;
  ws->q = ws->used_cubic ? ws->cubic_guess : ws->damped_guess;
}

// After a step to q(t_{k+1}): which guess came closer (in CorrectionNorm's metres), for the next.
// The cubic one only where the damped one missed by more than Newton's smallest correction
// (1e-10 of the rod length, sim/newton.cc: conditioning allows no better): below that there is
// nothing to extrapolate but rounding, which the cubic's weights (3, −3, 1 on q̇) amplify, and
// the solution accepts within its tolerance (a helix at rest drifted 4e-12 m in 1000 steps
// instead of less than 1e-12: tests/validation, RestHelix).
void ChoosePredictor(const Model& model, const VecX& q, Workspace* ws) {
  ws->damped_miss = CorrectionDistance(model, q, ws->damped_guess);
  ws->cubic_predictor = ws->have_cubic_guess &&
                        ws->damped_miss > 1e-10 * model.length_scale &&
                        CorrectionDistance(model, q, ws->cubic_guess) < ws->damped_miss;
}

StepReport StepOnce(const Model& model, double h, State* state, Workspace* ws) {
  StepReport report;
  // Contact rounds after the first start from the previous round's solution.
  Predict(model, h, *state, ws);
  const bool have_previous = ws->previous_velocity.size() == state->velocity.size();
  const bool implicit_drag = ws->nonlocal_fluid && model.coupling != FluidCoupling::kExplicit;
  if (implicit_drag) PredictDrag(h, ws);

  // Every step is solved in implicit Euler's form, v(q) = (q − q̃)/h_e and M (v(q) − ṽ)/h_e =
  // F(q, v(q)): implicit Euler has q̃ = q_k, ṽ = q̇_k, h_e = h; BDF2 (from the second step at an
  // unchanged h) has q̃ = (4q_k − q_{k−1})/3, ṽ = (4q̇_k − q̇_{k−1})/3, h_e = 2h/3, and takes the
  // mobility and the local drag at the predictor (second order) instead of at q_k. Free bodies
  // likewise (sim/bodies.h: BodyStep).
  const bool bdf2 = model.integrator == TimeIntegrator::kBdf2 && have_previous &&
                    ws->previous_q.size() == state->q.size() && ws->previous_h == h &&
                    (model.num_free_bodies == 0 || ws->previous_poses.size() == model.bodies.size());
  const double he = bdf2 ? 2.0 * h / 3.0 : h;
  if (!model.bodies.empty()) {  // clamps on moving bodies go with them (to the predictor's poses)
    BodyStep& bodies = ws->body_step;
    bodies.current = bodies.start = state->bodies;
    if (ws->free_clamps) bodies.current_q = state->q;
    bodies.h = h;
    bodies.he = he;
    // The predictor's poses from the last step's V, not from the extrapolated first guess of the
    // drag: BDF2 takes 𝕄 there, and the extrapolation 3V_k − 3V_{k−1} + V_{k−2} multiplies an
    // alternating error by 7, which came back through 𝕄's geometry (measured: at h = 20 ms the
    // rigid swimmer's Ω off by 1.8e-2 instead of 1.2e-4).
    std::vector<BodyPose> next = state->bodies;
    AdvanceBodies(model, h, ws->drag_at_start, &next);
    DriveBodyClamps(model, state->bodies, next, &ws->q);
    for (std::size_t k = 0; k < model.bodies.size() && bdf2; ++k)
      if (model.bodies[k].motion == BodyMotion::kFree)
        bodies.start[k] = Bdf2StartPose(state->bodies[k], ws->previous_poses[k]);
    bodies.geometry = bdf2 ? next : state->bodies;
  }
  State& start = ws->step_start;
  start.time = state->time;
  start.step = state->step;
  start.bodies = state->bodies;
  if (bdf2) {
    start.q = (4.0 * state->q - ws->previous_q) / 3.0;
    start.velocity = (4.0 * state->velocity - ws->previous_velocity) / 3.0;
  } else {
    start.q = state->q;
    start.velocity = state->velocity;
  }
  std::swap(start.rods, state->rods);  // the frames at q_k, lent for the step
  struct GiveBack {
    State* from;
    State* to;
    ~GiveBack() { std::swap(from->rods, to->rods); }
  } give_back{&start, state};
  if (bdf2) {
    State& geometry = ws->step_geometry;  // where the step's mobility and local drag are taken
    geometry.q = ws->q;  // the damped guess (BDF2 takes no other), clamps on bodies placed
    geometry.velocity = state->velocity;
    geometry.time = state->time + h;  // the predictor's time: the bodies' (known) poses there
    geometry.bodies = ws->body_step.geometry;
    PrepareStep(model, geometry, ws);
  } else {
    PrepareStep(model, start, ws);
  }

  // Clamps on free bodies where the first guess's V puts them (Φ(V), as every Newton trial does).
  if (ws->free_clamps) PlaceFreeClamps(model, ws->body_step, ws->hydro_force, &ws->q);
  // Newton starts from the guess with each edge at its extrapolated length (SetEdgeLengths). After
  // every placement: BDF2 takes its geometry at the guess as predicted. ChoosePredictor compares
  // the two guesses as extrapolated (setting the lengths on all three made the same choices on
  // paper Fig. 1 at 1 and 10 ms and on the regression case, at three times the cost).
  const VecX* before =
      ws->previous_q.size() == state->q.size() && ws->previous_h == h ? &ws->previous_q : nullptr;
  ExtrapolateEdgeLengths(model, state->q, before, &ws->edge_lengths);
  SetEdgeLengths(model, ws->edge_lengths, &ws->q);
  if (ws->nonlocal_fluid) ws->hydro.ResetSolveReport();
  for (report.contact_rounds = 1;; ++report.contact_rounds) {
    const NewtonReport newton = SolveNewton(model, start, he, ws);
    report.newton_iterations += newton.iterations;
    report.krylov_iterations += newton.krylov_iterations;
    if (!newton.converged) {
      if (implicit_drag) ws->hydro_force = ws->drag_at_start;  // as before the step
      report.message = fmt::format(
          "Newton did not converge at t = {:.6g} s: residual {:.3e} N > tolerance {:.3e} N after "
          "{} iterations, {}; try a smaller run.time_step, or solver.max_step_halvings to halve "
          "the steps that fail",
          state->time + h, newton.residual, newton.tolerance, newton.iterations,
          DescribeResidual(model, ws->residual));
      report.message += DescribeConvergence(model, newton);
      if (ws->nonlocal_fluid && !ws->hydro.worst_solve().ok)
        report.message += fmt::format(
            "; a GMRES solve of the drag stopped at a relative residual of {:.1e} after {} "
            "products (try fluid.solver = \"direct\" or a smaller time step)",
            ws->hydro.worst_solve().relative_residual, ws->hydro.worst_solve().krylov_iterations);
      return report;
    }
    if (!model.contact) break;
    if (!ws->factors_valid || ws->factors_h != he) {  // the response needs the Newton matrix
      Evaluate(model, start, he, ws->q, ws->hydro_force, true, ws, &ws->frames, &ws->residual);
      ws->factors_valid = FactorizeJacobian(model, he, ws);
      ws->factors_h = he;
      ws->factors_age = 0;
    }
    // The rods' DOFs take F as −F in r_q, the free bodies' rows L as +L in r_u: the response is
    // the Newton correction of those increments, the drag and (U, Ω) responding with the rods.
    const LinearResponse respond = [&](const VecX& force, const VecX& body_load, VecX* dq,
                                       VecX* dv) {
      VecX r_u = VecX::Zero(ws->nonlocal_fluid ? model.hydro_size() : 0), df, du;
      r_u.tail(body_load.size()) = body_load;
      report.krylov_iterations += NewtonCorrection(model, he, -force, r_u, ws, dq, &df, &du);
      *dv = df.tail(body_load.size());
    };
    std::vector<BodyPose> poses;  // at the step's end, with the current V
    if (!model.bodies.empty()) EndPoses(model, ws->body_step, ws->hydro_force, &poses);
    report.contact = AddContactForces(model, ws->q, he, respond, &ws->contact_force, poses,
                                      &ws->body_load, &ws->contact_candidates);
    if (report.contact.active == 0) break;  // report.contact describes the final state
    report.contact_pairs = std::max(report.contact_pairs, report.contact.detected);
    if (report.contact_rounds >= model.newton.max_contact_rounds) {
      if (implicit_drag) ws->hydro_force = ws->drag_at_start;
      report.message = fmt::format(
          "contact not resolved at t = {:.6g} s: {} pairs still closer than the contact distance "
          "after {} rounds, the deepest {} (penetration {:.3e} m, {:.2g} of the contact "
          "distance); try a smaller run.time_step, a larger contact.max_rounds, or "
          "solver.max_step_halvings",
          state->time + h, report.contact.active, report.contact_rounds,
          DescribeDeepest(report.contact), report.contact.max_penetration,
          report.contact.max_penetration / report.contact.deepest_contact_distance);
      return report;
    }
  }
  if (implicit_drag) RememberDrag(h, ws);
  ChoosePredictor(model, ws->q, ws);
  std::swap(ws->older_velocity, ws->previous_velocity);
  ws->older_h = ws->previous_h;
  ws->previous_velocity = state->velocity;
  ws->previous_q = state->q;
  ws->previous_h = h;
  ws->previous_poses = state->bodies;
  state->velocity = (ws->q - start.q) / he;
  state->q = ws->q;
  if (!model.bodies.empty()) EndPoses(model, ws->body_step, ws->hydro_force, &state->bodies);
  std::swap(start.rods, ws->frames);  // the new frames go to the state by give_back;
                                      // ws->frames is rewritten by the next Evaluate
  state->time += h;
  ++state->step;
  ++ws->factors_age;
  report.ok = true;
  return report;
}

}  // namespace

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
