#include "stokesrods/sim/hydro_coupling.h"

#include <algorithm>

#include "stokesrods/common/assert.h"
#include "stokesrods/sim/state.h"

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

void HydroCoupling::Prepare(const Model& model, const VecX& q_start, const VecX& v_start) {
  std::vector<Matrix3X> positions;
  for (int r = 0; r < static_cast<int>(model.rods.size()); ++r)
    positions.push_back(RodPositions(model, r, q_start));
  AssembleMobility(model.fluid, MakeHydroRods(model, positions), &mobility_);
  lu_.compute(mobility_);
  explicit_ = model.coupling == FluidCoupling::kExplicit;
  if (explicit_) {
    GatherNodeVelocities(model, v_start, VecX::Zero(v_start.size()), 1.0, &velocity_);
    explicit_force_ = -lu_.solve(velocity_);
  }
}

void HydroCoupling::AddTo(const Model& model, const StepContext& ctx, const VecX& q,
                          VecX* force) {
  if (explicit_) {
    nodal_force_ = explicit_force_;
  } else {
    GatherNodeVelocities(model, q, *ctx.q_start, ctx.time_step, &velocity_);
    nodal_force_ = -lu_.solve(velocity_);
  }
  for (const RodModel& rod : model.rods)
    for (int i = 0; i < rod.num_nodes(); ++i)
      force->segment<3>(rod.dof_offset + NodeDof(i)) +=
          nodal_force_.segment<3>(3 * (rod.node_offset + i));
}

bool HydroCoupling::FactorizeNewtonSystem(const Model& model, double h,
                                          std::vector<BandedMatrix>* jacobian) {
  SR_ASSERT(!explicit_, "the Woodbury solve is for the implicit coupling");
  capacitance_ = h * mobility_;
  x_blocks_.resize(model.rods.size());
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
    // The block S_k X_k of the capacitance h 𝕄 + S X (rows of fixed DOFs of X are zero).
    const int first = 3 * rod.node_offset;
    for (int i = 0; i < n; ++i)
      capacitance_.block(first + 3 * i, first, 3, 3 * n) += x.middleRows<3>(NodeDof(i));
  }
  capacitance_lu_.compute(capacitance_);
  return true;
}

void HydroCoupling::SolveNewtonSystem(const Model& model, const std::vector<BandedMatrix>& jacobian,
                                      VecX* rhs) {
  // J⁻¹ r = y − X (h 𝕄 + S X)⁻¹ S y,  y = B⁻¹ r.
  velocity_.resize(3 * model.num_nodes);
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodModel& rod = model.rods[r];
    jacobian[r].Solve(rhs->data() + rod.dof_offset, 1);
    for (int i = 0; i < rod.num_nodes(); ++i)
      velocity_.segment<3>(3 * (rod.node_offset + i)) = rhs->segment<3>(rod.dof_offset + NodeDof(i));
  }
  const VecX z = capacitance_lu_.solve(velocity_);
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodModel& rod = model.rods[r];
    rhs->segment(rod.dof_offset, rod.num_dofs()) -=
        x_blocks_[r] * z.segment(3 * rod.node_offset, 3 * rod.num_nodes());
  }
}

}  // namespace stokesrods
