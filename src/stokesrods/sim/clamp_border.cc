#include "stokesrods/sim/clamp_border.h"

#include <algorithm>

#include "stokesrods/common/assert.h"

namespace stokesrods {

namespace {

const BodyModel* FreeBodyOf(const Model& model, const RodModel& rod) {
  if (rod.body < 0) return nullptr;
  const BodyModel& body = model.bodies[static_cast<std::size_t>(rod.body)];
  return body.motion == BodyMotion::kFree ? &body : nullptr;
}

int VelocityIndex(const Model& model, const BodyModel& body) {
  return 3 * model.num_hydro_points() + 6 * body.free_index;
}

}  // namespace

bool HasFreeClamps(const Model& model) {
  return std::any_of(model.rods.begin(), model.rods.end(),
                     [&](const RodModel& rod) { return FreeBodyOf(model, rod) != nullptr; });
}

MatX ClampRigidMotions(const Model& model, int r, const std::vector<BodyPose>& start_poses,
                       const VecX& q) {
  const RodModel& rod = model.rods[static_cast<std::size_t>(r)];
  const Vec3 center = start_poses[static_cast<std::size_t>(rod.body)].center;
  const int o = rod.dof_offset;
  const Vec3 tangent = (q.segment<3>(o + NodeDof(1)) - q.segment<3>(o + NodeDof(0))).normalized();
  MatX g = MatX::Zero(static_cast<Eigen::Index>(rod.fixed_dofs.size()), 6);
  for (std::size_t a = 0; a < rod.fixed_dofs.size(); ++a) {
    const int k = rod.fixed_dofs[a], c = k % 4;
    const auto row = static_cast<Eigen::Index>(a);
    if (c == 3) {  // θ0 turns with the body's spin about the first edge
      g.block<1, 3>(row, 3) = tangent.transpose();
      continue;
    }
    // (δΩ × r)_c = (r × e_c) · δΩ
    const Vec3 arm = q.segment<3>(o + NodeDof(k / 4)) - center;
    g(row, c) = 1.0;
    g.block<1, 3>(row, 3) = arm.cross(Vec3::Unit(c)).transpose();
  }
  return g;
}

void CaptureClampBorders(const Model& model, const std::vector<BodyPose>& start_poses,
                         const VecX& q, const std::vector<BandedMatrix>& jacobian,
                         std::vector<ClampBorder>* borders) {
  borders->clear();
  for (int r = 0; r < static_cast<int>(model.rods.size()); ++r) {
    const RodModel& rod = model.rods[static_cast<std::size_t>(r)];
    const BodyModel* body = FreeBodyOf(model, rod);
    if (body == nullptr) continue;
    const BandedMatrix& b = jacobian[static_cast<std::size_t>(r)];
    const int n = rod.num_dofs(), kd = b.half_bandwidth();
    const auto nc = static_cast<Eigen::Index>(rod.fixed_dofs.size());
    ClampBorder border;
    border.rod = r;
    border.unknown = VelocityIndex(model, *body);
    border.dofs = rod.fixed_dofs;
    border.g = ClampRigidMotions(model, r, start_poses, q);
    border.columns = MatX::Zero(n, nc);
    border.rows = MatX::Zero(nc, n);
    for (Eigen::Index a = 0; a < nc; ++a) {
      const int k = rod.fixed_dofs[static_cast<std::size_t>(a)];
      for (int j = std::max(0, k - kd); j <= std::min(n - 1, k + kd); ++j) {
        border.rows(a, j) = b(k, j);
        if (!std::binary_search(rod.fixed_dofs.begin(), rod.fixed_dofs.end(), j))
          border.columns(j, a) = b(j, k);
      }
    }
    borders->push_back(std::move(border));
  }
}

void ClampLoads(const Model& model, const std::vector<BodyPose>& start_poses, const VecX& q,
                const VecX& residual, VecX* loads) {
  loads->setZero(6 * model.num_free_bodies);
  for (int r = 0; r < static_cast<int>(model.rods.size()); ++r) {
    const RodModel& rod = model.rods[static_cast<std::size_t>(r)];
    const BodyModel* body = FreeBodyOf(model, rod);
    if (body == nullptr) continue;
    const MatX g = ClampRigidMotions(model, r, start_poses, q);
    VecX reaction(g.rows());
    for (std::size_t a = 0; a < rod.fixed_dofs.size(); ++a)
      reaction(static_cast<Eigen::Index>(a)) = residual(rod.dof_offset + rod.fixed_dofs[a]);
    loads->segment<6>(6 * body->free_index) += g.transpose() * reaction;
  }
}

void CompleteClampBorders(const Model& model, const std::vector<BandedMatrix>& factorized,
                          std::vector<ClampBorder>* borders) {
  for (ClampBorder& border : *borders) {
    const RodModel& rod = model.rods[static_cast<std::size_t>(border.rod)];
    // Γ = E_c G_c − B̃⁻¹ B_{:,c} G_c
    border.gamma = -(border.columns * border.g);
    factorized[static_cast<std::size_t>(border.rod)].Solve(&border.gamma);
    for (std::size_t a = 0; a < rod.fixed_dofs.size(); ++a)
      border.gamma.row(rod.fixed_dofs[a]) += border.g.row(static_cast<Eigen::Index>(a));
    border.k = -(border.g.transpose() * (border.rows * border.gamma));
  }
}

void AddClampBordersToCapacitance(const Model& model, double h,
                                  const std::vector<ClampBorder>& borders, MatX* capacitance) {
  for (const ClampBorder& border : borders) {
    const RodModel& rod = model.rods[static_cast<std::size_t>(border.rod)];
    const int v = border.unknown, first = 3 * rod.node_offset;
    for (int i = 0; i < rod.num_nodes(); ++i)
      capacitance->block<3, 6>(first + 3 * i, v) += h * border.gamma.middleRows<3>(NodeDof(i));
    // h G_cᵀ (S_cᵀ − B_{c,:} X) on the rod's nodal forces
    MatX coupling = -border.row_x;
    for (std::size_t a = 0; a < border.dofs.size(); ++a) {
      const int k = border.dofs[a];
      if (k % 4 != 3) coupling(static_cast<Eigen::Index>(a), 3 * (k / 4) + k % 4) += 1.0;
    }
    capacitance->block(v, first, 6, coupling.cols()) += h * border.g.transpose() * coupling;
    capacitance->block<6, 6>(v, v) += h * h * border.k;
  }
}

void ApplyClampBorders(const Model& model, double h, const std::vector<ClampBorder>& borders,
                       const VecX& v, const VecX& z, VecX* out) {
  for (const ClampBorder& border : borders) {
    const RodModel& rod = model.rods[static_cast<std::size_t>(border.rod)];
    const Vec6 dv = v.segment<6>(border.unknown);
    const Vec6 motion = h * dv;
    for (int i = 0; i < rod.num_nodes(); ++i)
      out->segment<3>(3 * (rod.node_offset + i)) += border.gamma.middleRows<3>(NodeDof(i)) * motion;
    VecX reaction = -(border.rows * z.segment(rod.dof_offset, rod.num_dofs()));
    for (std::size_t a = 0; a < border.dofs.size(); ++a) {
      const int k = border.dofs[a];
      if (k % 4 != 3) reaction(static_cast<Eigen::Index>(a)) += v(3 * rod.node_offset + 3 * (k / 4) + k % 4);
    }
    out->segment<6>(border.unknown) += h * (border.g.transpose() * reaction) + h * h * (border.k * dv);
  }
}

void AddClampBorderRhs(const Model& model, double h, const std::vector<ClampBorder>& borders,
                       const VecX& y, VecX* sy) {
  for (const ClampBorder& border : borders) {
    const RodModel& rod = model.rods[static_cast<std::size_t>(border.rod)];
    sy->segment<6>(border.unknown) -=
        h * (border.g.transpose() * (border.rows * y.segment(rod.dof_offset, rod.num_dofs())));
  }
}

void AddClampMotion(const Model& model, double h, const std::vector<ClampBorder>& borders,
                    const VecX& df, VecX* dq) {
  for (const ClampBorder& border : borders) {
    const RodModel& rod = model.rods[static_cast<std::size_t>(border.rod)];
    dq->segment(rod.dof_offset, rod.num_dofs()) += h * (border.gamma * df.segment<6>(border.unknown));
  }
}

}  // namespace stokesrods
