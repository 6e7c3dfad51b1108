// Newton's method for one implicit step (sim/integrator.h's Step and SolveStatic): the residual's
// norms and tolerance, the Newton matrix's factorization and corrections (banded, or the saddle
// system of the implicit nonlocal drag, sim/hydro_coupling.h), the globalized iteration, and the
// messages that describe a failure. Internal to the sim module.
#pragma once

#include <string>

#include "stokesrods/common/types.h"
#include "stokesrods/sim/integrator.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {

/// The implicit nonlocal drag: f is an unknown beside q (sim/hydro_coupling.h).
bool UsesSaddle(const Model& model, double h, const Workspace& ws);

/// Factorizes the Newton matrix assembled in ws->jacobian (in place). False on a zero pivot.
bool FactorizeJacobian(const Model& model, double h, Workspace* ws);

/// The Newton correction with the current factors: dq = −J⁻¹ r for the banded problem; with the
/// implicit nonlocal drag, (dq, df) solve the saddle system for (r, r_u) and du is the change of
/// r_u along them. Returns the Krylov iterations it took.
int NewtonCorrection(const Model& model, double h, const VecX& residual, const VecX& r_u,
                     Workspace* ws, VecX* dq, VecX* df, VecX* du, double velocity_tolerance = 0.0);

/// Newton's method from the iterate in ws->q to the step's solution (see newton.cc for the
/// globalization and the reuse of the factors).
NewtonReport SolveNewton(const Model& model, const State& start, double h, Workspace* ws);

/// Where a residual is largest, or first not finite: "largest at rod 2, node 14 (a force)".
std::string DescribeResidual(const Model& model, const VecX& r);
/// Size of a correction (or any difference of q) in metres: positions as they are, twist angles
/// times their edge length.
double CorrectionNorm(const Model& model, const VecX& delta);
/// CorrectionNorm(a − b) without forming the difference.
double CorrectionDistance(const Model& model, const VecX& a, const VecX& b);

/// How the iterations went, when that points to a remedy (damped iterations, a last iteration
/// still converging fast); empty otherwise.
std::string DescribeConvergence(const Model& model, const NewtonReport& newton);

}  // namespace stokesrods
