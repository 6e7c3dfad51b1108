#include "stokesrods/sim/forces.h"

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/hydrodynamics.h"

namespace stokesrods {

void ConstantLoads::AddTo(const Model& model, const StepContext& ctx, const VecX& /*q*/,
                          VecX* force, std::vector<BandedMatrix>* /*jacobian*/) const {
  for (const RodModel& rod : model.rods) {
    for (const PointLoad& load : rod.loads)
      force->segment<3>(rod.dof_offset + NodeDof(load.node)) += ctx.load_factor * load.force;
    if (model.gravity.squaredNorm() == 0.0) continue;
    for (int i = 0; i < rod.num_nodes(); ++i) {
      const int k = rod.dof_offset + NodeDof(i);
      force->segment<3>(k) += ctx.load_factor * rod.mass(NodeDof(i)) * model.gravity;
    }
  }
}

void LocalDrag::CalcResistance(const Model& model, const VecX& q_start,
                               Eigen::MatrixX3d* blocks) const {
  blocks->resize(3 * model.num_nodes, 3);
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodModel& rod = model.rods[r];
    const int n = rod.num_nodes();
    auto x = [&](int i) { return Vec3(q_start.segment<3>(rod.dof_offset + NodeDof(i))); };
    for (int i = 0; i < n; ++i) {
      const Vec3 tangent = (x(std::min(i + 1, n - 1)) - x(std::max(i - 1, 0))).normalized();
      const double before = i > 0 ? (x(i) - x(i - 1)).norm() : 0.0;
      const double after = i + 1 < n ? (x(i + 1) - x(i)).norm() : 0.0;
      const double dl = 0.5 * (before + after);
      const Mat3 tt = tangent * tangent.transpose();
      const double c_par = coefficients_[r](0), c_perp = coefficients_[r](1);
      blocks->middleRows<3>(3 * (rod.node_offset + i)) =
          dl * (c_par * tt + c_perp * (Mat3::Identity() - tt));
    }
  }
}

void LocalDrag::AddTo(const Model& model, const StepContext& ctx, const VecX& q, VecX* force,
                      std::vector<BandedMatrix>* jacobian) const {
  if (ctx.time_step <= 0.0) return;  // static: no velocity, no drag
  SR_ASSERT(blocks_.rows() == 3 * model.num_nodes, "LocalDrag::Prepare was not called");
  const double h = ctx.time_step;
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodModel& rod = model.rods[r];
    for (int i = 0; i < rod.num_nodes(); ++i) {
      const int k = rod.dof_offset + NodeDof(i);
      const Mat3 c = blocks_.middleRows<3>(3 * (rod.node_offset + i));
      force->segment<3>(k) -= c * (q.segment<3>(k) - ctx.q_start->segment<3>(k)) / h;
      if (jacobian) (*jacobian)[r].AddBlock(NodeDof(i), c / h);
    }
  }
}

std::vector<std::unique_ptr<ExternalForce>> MakeLocalForces(const Model& model) {
  std::vector<std::unique_ptr<ExternalForce>> forces;
  forces.push_back(std::make_unique<ConstantLoads>());
  std::vector<Vec2> coefficients(model.rods.size(), Vec2::Zero());
  bool any = false;
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    if (model.damping > 0.0) coefficients[r] += Vec2(model.damping, model.damping);
    if (model.fluid.model == FluidModel::kRft) coefficients[r] += model.rods[r].rft_coefficients;
    any = any || coefficients[r].squaredNorm() > 0.0;
  }
  if (any) forces.push_back(std::make_unique<LocalDrag>(std::move(coefficients)));
  return forces;
}

}  // namespace stokesrods
