#include "stokesrods/sim/hydro_coupling.h"

#include <algorithm>

#include "stokesrods/common/assert.h"
#include "stokesrods/sim/state.h"
#include "stokesrods/solver/gmres.h"

namespace stokesrods {

void GatherNodeVelocities(const Model& model, const VecX& q, const VecX& q_start, double h,
                          VecX* u) {
  u->resize(3 * model.num_nodes);
  for (const RodModel& rod : model.rods)
    for (int i = 0; i < rod.num_nodes(); ++i) {
      const int k = rod.dof_offset + NodeDof(i);
      u->segment<3>(3 * (rod.node_offset + i)) = (q.segment<3>(k) - q_start.segment<3>(k)) / h;
    }
}

std::vector<HydroRod> MakeHydroRods(const Model& model, const std::vector<Matrix3X>& positions) {
  std::vector<HydroRod> rods(model.rods.size());
  for (std::size_t r = 0; r < rods.size(); ++r) {
    rods[r].x = &positions[r];
    rods[r].radius = model.rods[r].radius;
    rods[r].rft_parallel = model.rods[r].rft_coefficients(0);
    rods[r].rft_perpendicular = model.rods[r].rft_coefficients(1);
  }
  return rods;
}

void HydroCoupling::Init(const Model& model) {
  mobility_ = MakeMobilityOperator(model.fluid, model.hydro.mobility);
  krylov_ = model.hydro.solver == HydroSolver::kKrylov;
  explicit_ = model.coupling == FluidCoupling::kExplicit;
  block_preconditioner_ = mobility_->matrix() == nullptr;
  SR_ASSERT(krylov_ || !block_preconditioner_, "the direct solve needs a dense mobility");
}

HydroSolveReport HydroCoupling::Prepare(const Model& model, const VecX& q_start,
                                        const VecX& v_start) {
  SR_ASSERT(mobility_ != nullptr, "HydroCoupling::Init was not called");
  positions_.resize(model.rods.size());
  for (int r = 0; r < static_cast<int>(model.rods.size()); ++r)
    positions_[static_cast<size_t>(r)] = RodPositions(model, r, q_start);
  mobility_->Update(MakeHydroRods(model, positions_));
  mobility_changed_ = true;
  HydroSolveReport report;
  if (!explicit_) return report;
  // The explicit drag: 𝕄 f = −U(t_k).
  VecX u;
  GatherNodeVelocities(model, v_start, VecX::Zero(v_start.size()), 1.0, &u);
  if (const MatX* m = mobility_->matrix()) {
    explicit_force_ = -m->partialPivLu().solve(u);
    return report;
  }
  if (mobility_block_lu_.empty() || ++mobility_blocks_age_ >= model.newton.jacobian_max_age) {
    mobility_block_lu_.clear();
    for (int r = 0; r < mobility_->num_rods(); ++r)
      mobility_block_lu_.emplace_back(mobility_->SelfBlock(r));
    mobility_blocks_age_ = 0;
  }
  const LinearOperator apply = [&](const VecX& x, VecX* y) { mobility_->Apply(x, y); };
  const LinearOperator precondition = [&](const VecX& x, VecX* y) {
    y->resize(x.size());
    for (int r = 0; r < mobility_->num_rods(); ++r) {
      const int first = 3 * mobility_->node_offset(r);
      const int n = 3 * (mobility_->node_offset(r + 1) - mobility_->node_offset(r));
      y->segment(first, n) = mobility_block_lu_[static_cast<size_t>(r)].solve(x.segment(first, n));
    }
  };
  if (explicit_force_.size() != u.size()) explicit_force_.setZero(u.size());
  VecX negative_u = -u;
  const GmresReport g = SolveGmres(apply, precondition, negative_u,
                                   {.tolerance = model.hydro.krylov_tolerance}, &explicit_force_);
  krylov_total_ += g.iterations;
  report.ok = g.converged;
  report.krylov_iterations = g.iterations;
  report.relative_residual = g.relative_residual;
  return report;
}

void HydroCoupling::AddNodalForce(const Model& model, const VecX& f, VecX* force) {
  for (const RodModel& rod : model.rods)
    for (int i = 0; i < rod.num_nodes(); ++i)
      force->segment<3>(rod.dof_offset + NodeDof(i)) += f.segment<3>(3 * (rod.node_offset + i));
}

void HydroCoupling::VelocityResidual(const Model& model, const VecX& q, const VecX& q_start,
                                     double h, const VecX& f, VecX* r_u) const {
  mobility_->Apply(f, r_u);
  GatherNodeVelocities(model, q, q_start, h, &scratch_);  // fixed nodes: zero
  *r_u += scratch_;
}

bool HydroCoupling::FactorizeNewtonSystem(const Model& model, double h,
                                          std::vector<BandedMatrix>* jacobian) {
  SR_ASSERT(!explicit_, "the capacitance solve is for the implicit coupling");
  x_blocks_.resize(model.rods.size());
  sx_blocks_.resize(model.rods.size());
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodModel& rod = model.rods[r];
    const int n = rod.num_nodes();
    BandedMatrix& b = (*jacobian)[r];
    if (!b.Factorize()) return false;
    // X_k = B_k⁻¹ S_kᵀ: a unit right-hand side per free position DOF (fixed ones stay zero).
    MatX& x = x_blocks_[r];
    x = MatX::Zero(rod.num_dofs(), 3 * n);
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        if (!std::binary_search(rod.fixed_dofs.begin(), rod.fixed_dofs.end(), NodeDof(i) + c))
          x(NodeDof(i) + c, 3 * i + c) = 1.0;
    b.Solve(&x);
    MatX& sx = sx_blocks_[r];
    sx.resize(3 * n, 3 * n);
    for (int i = 0; i < n; ++i) sx.middleRows<3>(3 * i) = x.middleRows<3>(NodeDof(i));
  }
  if (block_preconditioner_) {
    block_lu_.clear();
    for (std::size_t r = 0; r < model.rods.size(); ++r)
      block_lu_.emplace_back(h * mobility_->SelfBlock(static_cast<int>(r)) + sx_blocks_[r]);
  } else {
    MatX capacitance = h * *mobility_->matrix();
    for (std::size_t r = 0; r < model.rods.size(); ++r) {
      const int first = 3 * model.rods[r].node_offset, n = static_cast<int>(sx_blocks_[r].rows());
      capacitance.block(first, first, n, n) += sx_blocks_[r];
    }
    capacitance_lu_.compute(capacitance);
  }
  mobility_changed_ = false;
  iterations_after_refresh_ = -1;
  wants_refresh_ = false;
  return true;
}

void HydroCoupling::ApplyCapacitance(const Model& model, double h, const VecX& v,
                                     VecX* out) const {
  mobility_->Apply(v, out);
  *out *= h;
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const int first = 3 * model.rods[r].node_offset, n = static_cast<int>(sx_blocks_[r].rows());
    out->segment(first, n).noalias() += sx_blocks_[r] * v.segment(first, n);
  }
}

void HydroCoupling::Precondition(const VecX& v, VecX* out) const {
  if (!block_preconditioner_) {
    *out = capacitance_lu_.solve(v);
    return;
  }
  out->resize(v.size());
  for (int r = 0; r < mobility_->num_rods(); ++r) {
    const int first = 3 * mobility_->node_offset(r);
    const int n = 3 * (mobility_->node_offset(r + 1) - mobility_->node_offset(r));
    out->segment(first, n) = block_lu_[static_cast<size_t>(r)].solve(v.segment(first, n));
  }
}

HydroSolveReport HydroCoupling::SolveNewtonSystem(const Model& model,
                                                  const std::vector<BandedMatrix>& jacobian,
                                                  double h, const VecX& r_q, const VecX& r_u,
                                                  VecX* dq, VecX* df, VecX* du,
                                                  double velocity_tolerance) {
  HydroSolveReport report;
  // y = −B⁻¹ r_q, and S y.
  *dq = -r_q;
  VecX sy(3 * model.num_nodes);
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodModel& rod = model.rods[r];
    jacobian[r].Solve(dq->data() + rod.dof_offset, 1);
    for (int i = 0; i < rod.num_nodes(); ++i)
      sy.segment<3>(3 * (rod.node_offset + i)) = dq->segment<3>(rod.dof_offset + NodeDof(i));
  }
  for (const RodModel& rod : model.rods)  // S selects free DOFs only (X has zero fixed rows)
    for (int k : rod.fixed_dofs)
      if (k % 4 != 3) sy(3 * rod.node_offset + 3 * (k / 4) + k % 4) = 0.0;
  const VecX b = -(h * r_u + sy);
  VecX cdf;  // C δf
  if (!krylov_) {
    SR_ASSERT(!mobility_changed_, "the direct solve needs the capacitance of the current 𝕄");
    *df = capacitance_lu_.solve(b);
    ApplyCapacitance(model, h, *df, &cdf);
    report.relative_residual = (b - cdf).norm() / std::max(b.norm(), 1e-300);
  } else {
    const LinearOperator apply = [&](const VecX& x, VecX* y) { ApplyCapacitance(model, h, x, y); };
    const LinearOperator precondition = [&](const VecX& x, VecX* y) { Precondition(x, y); };
    df->setZero(b.size());
    // r_u after the step is −(b − C δf)/h: its 2-norm bounds the ∞-norm the Newton test reads.
    const GmresReport g = SolveGmres(apply, precondition, b,
                                     {.tolerance = model.hydro.krylov_tolerance,
                                      .absolute_tolerance = h * velocity_tolerance},
                                     df, &cdf);
    report.ok = g.converged;
    report.krylov_iterations = g.iterations;
    report.relative_residual = g.relative_residual;
    krylov_total_ += g.iterations;
    if (iterations_after_refresh_ < 0) iterations_after_refresh_ = g.iterations;
    wants_refresh_ = g.iterations > 2 * iterations_after_refresh_ + 2;
  }
  // δq = y + X δf;  du = S δq/h + 𝕄 δf = (S y + C δf)/h.
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodModel& rod = model.rods[r];
    dq->segment(rod.dof_offset, rod.num_dofs()).noalias() +=
        x_blocks_[r] * df->segment(3 * rod.node_offset, 3 * rod.num_nodes());
  }
  *du = (sy + cdf) / h;
  return report;
}

}  // namespace stokesrods
