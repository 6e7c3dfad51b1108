#include "stokesrods/sim/capacitance_preconditioner.h"

#include <algorithm>
#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/common/parallel.h"

namespace stokesrods {

VecX CapacitancePreconditioner::Block::Gather(const VecX& v) const {
  VecX x(size);
  int k = 0;
  for (const auto& [first, n] : ranges) {
    x.segment(k, n) = v.segment(first, n);
    k += n;
  }
  return x;
}

void CapacitancePreconditioner::Block::Scatter(const Eigen::VectorXd& x, VecX* out) const {
  int k = 0;
  for (const auto& [first, n] : ranges) {
    out->segment(first, n) += x.segment(k, n);
    k += n;
  }
}

void CapacitancePreconditioner::MakeBlocks(const Model& model,
                                           const std::vector<BodySurface>& bodies) {
  const int num_rods = static_cast<int>(model.rods.size());
  const int num_bodies = static_cast<int>(bodies.size());
  blocks_.clear();
  rod_place_.assign(model.rods.size(), Place{});
  body_place_.assign(bodies.size(), Place{});
  auto add = [&](Block* block, Place* place, int first, int n) {
    *place = {.block = static_cast<int>(blocks_.size()), .offset = block->size};
    block->ranges.emplace_back(first, n);
    block->size += n;
  };
  for (int r = 0; r < num_rods; ++r) {
    const RodModel& rod = model.rods[static_cast<size_t>(r)];
    if (rod.body >= 0) continue;  // in its body's cell
    Block block;
    block.rod = r;
    add(&block, &rod_place_[static_cast<size_t>(r)], 3 * rod.node_offset, 3 * rod.num_nodes());
    blocks_.push_back(std::move(block));
  }
  for (int first = 3 * model.num_nodes, k = 0; k < num_bodies; ++k) {
    Block block;  // the body's rods, then its points
    block.body = k;
    for (int r = 0; r < num_rods; ++r) {
      const RodModel& rod = model.rods[static_cast<size_t>(r)];
      if (rod.body == k)
        add(&block, &rod_place_[static_cast<size_t>(r)], 3 * rod.node_offset, 3 * rod.num_nodes());
    }
    const int n = 3 * static_cast<int>(bodies[static_cast<size_t>(k)].points.cols());
    add(&block, &body_place_[static_cast<size_t>(k)], first, n);
    first += n;
    blocks_.push_back(std::move(block));
  }
}

MatX CapacitancePreconditioner::BlockMatrix(const Model& model, double h, const Block& block,
                                            const std::vector<MatX>& rod_blocks,
                                            const std::vector<HydroRod>& rods,
                                            const std::vector<BodySurface>& bodies) const {
  const Wall* wall = model.fluid.wall ? &*model.fluid.wall : nullptr;
  if (block.rod >= 0) return rod_blocks[static_cast<size_t>(block.rod)];
  const int body = block.body;
  const BodySurface& surface = bodies[static_cast<size_t>(body)];
  if (block.ranges.size() == 1)  // a body with no rods
    return h * PointStokesletMobility(surface, model.fluid.viscosity, wall);
  // A cell: h times the dense mobility of its rods and points, the rods' own blocks D_k.
  std::vector<HydroRod> cell_rods;
  std::vector<int> cell_rod_index;
  for (std::size_t r = 0; r < rods.size(); ++r)
    if (model.rods[r].body == body) {
      cell_rods.push_back(rods[r]);
      cell_rod_index.push_back(static_cast<int>(r));
    }
  MatX m = h * AssembleMobilityWithBodies(model.fluid, cell_rods, {surface});
  for (const int r : cell_rod_index) {
    const Place& place = rod_place_[static_cast<size_t>(r)];
    const MatX& d = rod_blocks[static_cast<size_t>(r)];
    m.block(place.offset, place.offset, d.rows(), d.cols()) = d;
  }
  return m;
}

bool CapacitancePreconditioner::Build(const Model& model, double h,
                                      const std::vector<MatX>& rod_blocks,
                                      const std::vector<HydroRod>& rods,
                                      const std::vector<BodySurface>& bodies,
                                      const std::vector<ClampBorder>* borders, bool coarse,
                                      bool keep_coarse) {
  SR_ASSERT(rod_blocks.size() == model.rods.size() && rods.size() == model.rods.size() &&
                bodies.size() == model.bodies.size(),
            "preconditioner: one block per rod and per body");
  MakeBlocks(model, bodies);
  size_ = 3 * model.num_hydro_points() + 6 * model.num_free_bodies;
  const int num_blocks = static_cast<int>(blocks_.size());
  bool ok = true;
#pragma omp parallel for schedule(dynamic) reduction(&& : ok)
  for (int k = 0; k < num_blocks; ++k) {
    Block& block = blocks_[static_cast<size_t>(k)];
    ok = block.lu.Compute(BlockMatrix(model, h, block, rod_blocks, rods, bodies).cast<float>(),
                          LuStorage::kHalf) &&
         ok;
  }
  if (!ok) return false;
  free_bodies_.clear();
  for (int k = 0; k < static_cast<int>(bodies.size()); ++k)
    if (bodies[static_cast<size_t>(k)].free && !BuildFreeBody(model, h, k, bodies, borders))
      return false;
  const bool had_coarse = coarse_ && coarse_level_.num_chunks() > 0;
  coarse_ = coarse && !rods.empty();
  if (!coarse_) return true;
  if (keep_coarse && had_coarse) {
    coarse_kept_ = true;
    return true;
  }
  coarse_kept_ = false;
  std::vector<CoarseRod> coarse_rods(model.rods.size());
  for (std::size_t r = 0; r < rods.size(); ++r)
    coarse_rods[r] = {.x = rods[r].x,
                      .eps = model.fluid.regularization * model.rods[r].radius,
                      .node_offset = model.rods[r].node_offset,
                      .fixed_nodes = model.rods[r].clamped_nodes};
  return coarse_level_.Build(coarse_rods, rod_blocks, h / (8.0 * kPi * model.fluid.viscosity));
}

bool CapacitancePreconditioner::BuildFreeBody(const Model& model, double h, int body,
                                              const std::vector<BodySurface>& bodies,
                                              const std::vector<ClampBorder>* borders) {
  const BodyModel& bm = model.bodies[static_cast<size_t>(body)];
  const BodySurface& surface = bodies[static_cast<size_t>(body)];
  FreeBody fb;
  fb.unknown = 3 * model.num_hydro_points() + 6 * bm.free_index;
  Mat6 k = Mat6::Zero();
  // B and Cᵀ per block they touch (the body's own and its rods' blocks: one block for a cell).
  std::vector<std::pair<MatX, MatX>> parts;
  auto part = [&](const Place& place) -> std::pair<MatX, MatX>& {
    const auto it = std::find(fb.blocks.begin(), fb.blocks.end(), place.block);
    if (it != fb.blocks.end()) return parts[static_cast<size_t>(it - fb.blocks.begin())];
    const int n = blocks_[static_cast<size_t>(place.block)].size;
    fb.blocks.push_back(place.block);
    parts.emplace_back(MatX::Zero(n, 6), MatX::Zero(6, n));
    return parts.back();
  };
  // The body's own points: B = h G_b, Cᵀ = h G_bᵀ.
  {
    const Place& place = body_place_[static_cast<size_t>(body)];
    auto& [columns, rows] = part(place);
    for (Eigen::Index j = 0; j < surface.points.cols(); ++j) {
      const Mat3 arm = CrossMatrix(surface.points.col(j) - surface.center);
      const auto i = place.offset + 3 * j;
      columns.block<3, 3>(i, 0) = h * Mat3::Identity();
      columns.block<3, 3>(i, 3) = -h * arm;
      rows.block<3, 3>(0, i) = h * Mat3::Identity();
      rows.block<3, 3>(3, i) = h * arm;
    }
  }
  // Its rods (sim/clamp_border.h): B = h S Γ, Cᵀ = h G_cᵀ (S_cᵀ − B_c X), K = h² K_c.
  if (borders)
    for (const ClampBorder& border : *borders) {
      if (border.unknown != fb.unknown) continue;
      const RodModel& rod = model.rods[static_cast<size_t>(border.rod)];
      const Place& place = rod_place_[static_cast<size_t>(border.rod)];
      auto& [columns, rows] = part(place);
      for (int i = 0; i < rod.num_nodes(); ++i)
        columns.middleRows<3>(place.offset + 3 * i) = h * border.gamma.middleRows<3>(NodeDof(i));
      MatX coupling = -border.row_x;
      for (std::size_t a = 0; a < border.dofs.size(); ++a) {
        const int dof = border.dofs[a];
        if (dof % 4 != 3) coupling(static_cast<Eigen::Index>(a), 3 * (dof / 4) + dof % 4) += 1.0;
      }
      rows.middleCols(place.offset, 3 * rod.num_nodes()) = h * border.g.transpose() * coupling;
      k += h * h * border.k;
    }
  Mat6 schur = k;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const Block& block = blocks_[static_cast<size_t>(fb.blocks[p])];
    MatX solved = parts[p].first;
    for (int c = 0; c < 6; ++c) {
      Eigen::VectorXf x = solved.col(c).cast<float>();
      block.lu.Solve(&x);
      solved.col(c) = x.cast<double>();
    }
    schur -= parts[p].second * solved;
    fb.columns_solved.push_back(std::move(solved));
    fb.rows.push_back(std::move(parts[p].second));
  }
  fb.schur.compute(schur);
  if (!(std::abs(fb.schur.determinant()) > 0.0)) return false;
  free_bodies_.push_back(std::move(fb));
  return true;
}

void CapacitancePreconditioner::SolveBlocks(const VecX& v, VecX* out) const {
  out->setZero(v.size());
  const int num_blocks = static_cast<int>(blocks_.size());
  // A rod's factors take 76 KB in half precision (65 nodes), 7.6 MB for a hundred rods: more
  // than the caches keep between applications, so each streams them from memory. Each thread
  // takes consecutive blocks (static) and, while it solves one, brings the next one's factors
  // into L2 a little at a time (DenseLu::SolveThenPrefetch): a hundred blocks of 195, one thread,
  // from memory, 10.9 µs a block with the next one prefetched at once before each solve, 8.8
  // spread over it, 6.3 from cache (bench_step BM_BlockSolvesCold; docs/performance.md, session
  // 35; before session 13 without any prefetch, 1.2× slower).
  ForEachStatic(num_blocks, num_blocks > 1, [&](int k) {  // the blocks' entries are disjoint
    const Block& block = blocks_[static_cast<size_t>(k)];
    Eigen::VectorXf x = block.Gather(v).cast<float>();
    if (k + 1 < num_blocks)
      block.lu.SolveThenPrefetch(&x, blocks_[static_cast<size_t>(k) + 1].lu);
    else
      block.lu.Solve(&x);
    block.Scatter(x.cast<double>(), out);
  });
}

void CapacitancePreconditioner::SolveFine(const VecX& v, VecX* out) const {
  SolveBlocks(v, out);  // z = A⁻¹ v (zero in the free bodies' rows)
  for (const FreeBody& fb : free_bodies_) {
    Vec6 rhs = v.segment<6>(fb.unknown);
    for (std::size_t p = 0; p < fb.rows.size(); ++p)
      rhs -= fb.rows[p] * blocks_[static_cast<size_t>(fb.blocks[p])].Gather(*out);
    const Vec6 motion = fb.schur.solve(rhs);
    out->segment<6>(fb.unknown) = motion;
    for (std::size_t p = 0; p < fb.rows.size(); ++p)
      blocks_[static_cast<size_t>(fb.blocks[p])].Scatter(-fb.columns_solved[p] * motion, out);
  }
}

void CapacitancePreconditioner::Apply(const VecX& v, VecX* out, const RodRotations& fine,
                                      const RodRotations& coarse) const {
  SR_ASSERT(v.size() == size_, "preconditioner: vector of the wrong size");
  if (!coarse_ || !coarse_kept_) {  // one build: Q P₀ Qᵀ v
    if (fine.empty()) return Apply(v, out);
    turned_ = v;
    fine.Apply(true, &turned_);
    Apply(turned_, out);
    fine.Apply(false, out);
    return;
  }
  // The coarse level of an earlier build, at other positions: each level in its own frame,
  //   c = E⁻¹ Zᵀ Q_cᵀ v,   y = Q_c Z c + Q_f Fine⁻¹ Q_fᵀ (v − Q_c W c).
  turned_ = v;
  if (!coarse.empty()) coarse.Apply(true, &turned_);
  const VecX c = coarse_level_.Solve(turned_);
  coarse_level_.ApplyW(c, &coarse_w_);
  coarse_z_.setZero(v.size());
  coarse_level_.AddZ(c, &coarse_z_);
  if (!coarse.empty()) {  // both on the rods' nodes only (W and Z are zero elsewhere)
    coarse.Apply(false, &coarse_w_);
    coarse.Apply(false, &coarse_z_);
  }
  turned_ = v;
  turned_.head(coarse_w_.size()) -= coarse_w_;
  if (!fine.empty()) fine.Apply(true, &turned_);
  SolveFine(turned_, out);
  if (!fine.empty()) fine.Apply(false, out);
  *out += coarse_z_;
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
