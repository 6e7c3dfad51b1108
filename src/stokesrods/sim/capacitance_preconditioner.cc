#include "stokesrods/sim/capacitance_preconditioner.h"

#include <algorithm>
#include <cmath>

#include "stokesrods/common/assert.h"

namespace stokesrods {

namespace {

Mat3 Cross(const Vec3& a) {  // [a]× b = a × b
  Mat3 m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

}  // namespace

bool CapacitancePreconditioner::Build(const Model& model, double h,
                                      const std::vector<MatX>& rod_blocks,
                                      const std::vector<BodySurface>& bodies,
                                      const std::vector<ClampBorder>* borders,
                                      const std::vector<Matrix3X>* positions) {
  SR_ASSERT(rod_blocks.size() == model.rods.size() && bodies.size() == model.bodies.size(),
            "preconditioner: one block per rod and per body");
  const int num_rods = static_cast<int>(model.rods.size());
  const int num_blocks = num_rods + static_cast<int>(bodies.size());
  block_first_.assign(1, 0);
  for (const RodModel& rod : model.rods) block_first_.push_back(block_first_.back() + 3 * rod.num_nodes());
  for (const BodySurface& b : bodies)
    block_first_.push_back(block_first_.back() + 3 * static_cast<int>(b.points.cols()));
  size_ = block_first_.back() + 6 * model.num_free_bodies;
  block_lu_.assign(static_cast<size_t>(num_blocks), DenseLu<float>());
  const Wall* wall = model.fluid.wall ? &*model.fluid.wall : nullptr;
  bool ok = true;
#pragma omp parallel for schedule(dynamic) reduction(&& : ok)
  for (int k = 0; k < num_blocks; ++k) {
    const auto ku = static_cast<size_t>(k);
    if (k < num_rods) {
      ok = block_lu_[ku].Compute(rod_blocks[ku].cast<float>()) && ok;
    } else {
      const BodySurface& b = bodies[static_cast<size_t>(k - num_rods)];
      ok = block_lu_[ku].Compute(
               (h * PointStokesletMobility(b, model.fluid.viscosity, wall)).cast<float>()) && ok;
    }
  }
  if (!ok) return false;
  free_bodies_.clear();
  for (int k = 0; k < static_cast<int>(bodies.size()); ++k)
    if (bodies[static_cast<size_t>(k)].free && !BuildFreeBody(model, h, k, bodies, borders))
      return false;
  coarse_ = positions != nullptr && num_rods > 0;
  if (!coarse_) return true;
  std::vector<CoarseRod> rods(model.rods.size());
  for (std::size_t r = 0; r < rods.size(); ++r)
    rods[r] = {.x = &(*positions)[r],
               .eps = model.fluid.regularization * model.rods[r].radius,
               .node_offset = model.rods[r].node_offset};
  return coarse_level_.Build(rods, rod_blocks, h / (8.0 * kPi * model.fluid.viscosity));
}

bool CapacitancePreconditioner::BuildFreeBody(const Model& model, double h, int body,
                                              const std::vector<BodySurface>& bodies,
                                              const std::vector<ClampBorder>* borders) {
  const BodyModel& bm = model.bodies[static_cast<size_t>(body)];
  const BodySurface& surface = bodies[static_cast<size_t>(body)];
  FreeBody fb;
  fb.body = body;
  fb.unknown = 3 * model.num_hydro_points() + 6 * bm.free_index;
  Mat6 k = Mat6::Zero();
  // The body's own points: B = h G_b, Cᵀ = h G_bᵀ.
  const int block = static_cast<int>(model.rods.size()) + body;
  const auto np = surface.points.cols();
  MatX columns(3 * np, 6), rows(6, 3 * np);
  for (Eigen::Index j = 0; j < np; ++j) {
    const Mat3 arm = Cross(surface.points.col(j) - surface.center);
    columns.block<3, 3>(3 * j, 0) = h * Mat3::Identity();
    columns.block<3, 3>(3 * j, 3) = -h * arm;
    rows.block<3, 3>(0, 3 * j) = h * Mat3::Identity();
    rows.block<3, 3>(3, 3 * j) = h * arm;
  }
  std::vector<std::pair<int, std::pair<MatX, MatX>>> parts;
  parts.push_back({block, {std::move(columns), std::move(rows)}});
  // Its rods (sim/clamp_border.h): B = h S Γ, Cᵀ = h G_cᵀ (S_cᵀ − B_c X), K = h² K_c.
  if (borders)
    for (const ClampBorder& border : *borders) {
      if (border.unknown != fb.unknown) continue;
      const RodModel& rod = model.rods[static_cast<size_t>(border.rod)];
      MatX rod_columns(3 * rod.num_nodes(), 6);
      for (int i = 0; i < rod.num_nodes(); ++i)
        rod_columns.middleRows<3>(3 * i) = h * border.gamma.middleRows<3>(NodeDof(i));
      MatX coupling = -border.row_x;
      for (std::size_t a = 0; a < border.dofs.size(); ++a) {
        const int dof = border.dofs[a];
        if (dof % 4 != 3) coupling(static_cast<Eigen::Index>(a), 3 * (dof / 4) + dof % 4) += 1.0;
      }
      parts.push_back({border.rod, {std::move(rod_columns), h * border.g.transpose() * coupling}});
      k += h * h * border.k;
    }
  Mat6 schur = k;
  for (auto& [b, part] : parts) {
    MatX solved = part.first;
    for (int c = 0; c < 6; ++c) {
      Eigen::VectorXf x = solved.col(c).cast<float>();
      block_lu_[static_cast<size_t>(b)].Solve(&x);
      solved.col(c) = x.cast<double>();
    }
    schur -= part.second * solved;
    fb.first.push_back(block_first_[static_cast<size_t>(b)]);
    fb.columns_solved.push_back(std::move(solved));
    fb.rows.push_back(std::move(part.second));
  }
  fb.schur.compute(schur);
  if (!(std::abs(fb.schur.determinant()) > 0.0)) return false;
  free_bodies_.push_back(std::move(fb));
  return true;
}

void CapacitancePreconditioner::SolveBlocks(const VecX& v, VecX* out) const {
  out->setZero(v.size());
  const int num_blocks = static_cast<int>(block_lu_.size());
#pragma omp parallel for schedule(dynamic) if (num_blocks > 1)
  for (int k = 0; k < num_blocks; ++k) {
    const int first = block_first_[static_cast<size_t>(k)];
    const int n = block_first_[static_cast<size_t>(k) + 1] - first;
    Eigen::VectorXf x = v.segment(first, n).cast<float>();
    block_lu_[static_cast<size_t>(k)].Solve(&x);
    out->segment(first, n) = x.cast<double>();
  }
}

void CapacitancePreconditioner::SolveFine(const VecX& v, VecX* out) const {
  SolveBlocks(v, out);  // z = A⁻¹ v (zero in the free bodies' rows)
  for (const FreeBody& fb : free_bodies_) {
    Vec6 rhs = v.segment<6>(fb.unknown);
    for (std::size_t p = 0; p < fb.rows.size(); ++p)
      rhs -= fb.rows[p] * out->segment(fb.first[p], fb.rows[p].cols());
    const Vec6 motion = fb.schur.solve(rhs);
    out->segment<6>(fb.unknown) = motion;
    for (std::size_t p = 0; p < fb.rows.size(); ++p)
      out->segment(fb.first[p], fb.columns_solved[p].rows()) -= fb.columns_solved[p] * motion;
  }
}

void CapacitancePreconditioner::Apply(const VecX& v, VecX* out) const {
  SR_ASSERT(v.size() == size_, "preconditioner: vector of the wrong size");
  if (!coarse_) return SolveFine(v, out);
  // Coarse: c = E⁻¹ Zᵀ v; then the fine level on what it leaves, y = Zc + Fine⁻¹(v − Wc), W zero
  // on the bodies' rows.
  const VecX coarse = coarse_level_.Solve(v);
  VecX wc;
  coarse_level_.ApplyW(coarse, &wc);
  VecX rest = v;
  rest.head(wc.size()) -= wc;
  SolveFine(rest, out);
  coarse_level_.AddZ(coarse, out);
}

}  // namespace stokesrods
