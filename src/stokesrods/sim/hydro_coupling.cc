#include "stokesrods/sim/hydro_coupling.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include <Eigen/SVD>

#include "stokesrods/common/assert.h"
#include "stokesrods/common/parallel.h"
#include "stokesrods/fluid/mobility_sources.h"
#include "stokesrods/fluid/wall_sources.h"
#include "stokesrods/sim/bodies.h"
#include "stokesrods/sim/state.h"
#include "stokesrods/solver/blas.h"
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

void SolveRodsBanded(const Model& model, const std::vector<BandedMatrix>& jacobian, VecX* x) {
  const int num_rods = static_cast<int>(model.rods.size());
  auto solve = [&](int first, int last) {  // rods first … last − 1
    for (int r = first; r < last; r += 2) {
      const int count = std::min(2, last - r);
      const BandedMatrix* matrices[2];
      double* rhs[2];
      for (int k = 0; k < count; ++k) {
        const auto rod = static_cast<std::size_t>(r + k);
        matrices[k] = &jacobian[rod];
        rhs[k] = x->data() + model.rods[rod].dof_offset;
      }
      SolveEach(matrices, rhs, count);
    }
  };
  if (!Parallel(RodsInParallel(num_rods, model.num_nodes))) return solve(0, num_rods);
#pragma omp parallel
  {
#ifdef _OPENMP
    const int thread = omp_get_thread_num(), threads = omp_get_num_threads();
#else
    const int thread = 0, threads = 1;
#endif
    solve(num_rods * thread / threads, num_rods * (thread + 1) / threads);
  }
}

std::unique_ptr<MobilityOperator> MakeModelMobility(const Model& model) {
  // The dense 𝕄 holds the bodies and the wall's images; the matrix-free rods take them as
  // further sources around the free-space operator (the wall's images of every source last).
  FluidParams free_space = model.fluid;
  free_space.wall.reset();
  std::unique_ptr<MobilityOperator> op = MakeMobilityOperator(free_space, model.hydro.mobility);
  if (op->matrix() != nullptr) return MakeMobilityOperator(model.fluid, model.hydro.mobility);
  if (!model.bodies.empty())
    op = MakeMobilityWithBodySources(free_space, model.hydro.mobility, std::move(op));
  if (model.fluid.wall) op = MakeMobilityWithWallImages(model.fluid, model.hydro.mobility, std::move(op));
  return op;
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

// C += S X on each rod's diagonal block (X's rows at the rod's nodes), in C's precision.
template <typename Matrix>
void AddSchurBlocks(const Model& model, const std::vector<MatX>& sx_blocks, Matrix* capacitance) {
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const int first = 3 * model.rods[r].node_offset, n = static_cast<int>(sx_blocks[r].rows());
    capacitance->block(first, first, n, n) += sx_blocks[r].cast<typename Matrix::Scalar>();
  }
}

constexpr int kFullLuBelow = 3000;
// Steps a Krylov preconditioner is kept at most (it is rebuilt sooner when GMRES slows down).
// 40 since 2026-11-25 (was 20): with the dense 𝕄 extrapolated quadratically, Fig. 1 at h = 1 ms
// needs 1.85 GMRES products per step at 40 (1.58 at 20, 2.01 at 60), and a rebuild (the Schur
// blocks and the LU of C) costs as much as ~27 products: 40 is the cheaper (docs/performance.md).
constexpr int kPreconditionerMaxAge = 40;
// What a rebuild of the preconditioner costs in GMRES products (a product with 𝕄, its banded
// solves and a preconditioner solve): it is rebuilt once the solves since the last rebuild have
// taken this many products beyond the first solve's count each (rent or buy). The dense LU (the
// Schur blocks and the float LU of C): fitted on Fig. 1 over 75 s at h = 40 ms (390 × 390: a
// rebuild 1.45 ms, a product 60 µs). The two levels (the blocks' Schur parts and LUs, the coarse
// level): on ten helices at h = 10 ms 4, 8, 12, 24 and 48 were tried, 8 the fastest
// (docs/performance.md, session 19).
constexpr int kRebuildCostInProducts = 24;
constexpr int kBlockRebuildCostInProducts = 8;

// n_c³ / M of a hundred helices (n_c = 2400 coarse unknowns, M = 6500 nodes): the scale at which
// one coarse build per rebuild pays (docs/performance.md, session 39: at two hundred helices
// a period of 2 and at four hundred of 3–4 took the mean step down, at a hundred 2 was within
// the noise).
constexpr double kCoarseKeepScale = 2.1e6;

int CoarseRebuildPeriod(int coarse_unknowns, int nodes) {
  if (coarse_unknowns <= 0 || nodes <= 0) return 1;
  const double n = coarse_unknowns;
  const double ratio = n * n * n / (kCoarseKeepScale * nodes);
  return std::max(1, static_cast<int>(std::lround(std::sqrt(ratio))));
}

void HydroCoupling::Init(const Model& model) {
  mobility_ = MakeModelMobility(model);
  krylov_ = model.hydro.solver == HydroSolver::kKrylov;
  rotate_preconditioner_ = model.hydro.rotate_preconditioner;
  explicit_ = model.coupling == FluidCoupling::kExplicit;
  // The whole capacitance's LU while it is small; above 3(M + P) = 3000 its O((3(M + P))³)
  // rebuilds cost more than the extra GMRES products of the block preconditioner
  // (docs/performance.md).
  block_preconditioner_ = mobility_->matrix() == nullptr ||
                          (krylov_ && 3 * model.num_hydro_points() > kFullLuBelow);
  SR_ASSERT(model.bodies.empty() || !explicit_ || model.fluid.model != FluidModel::kRss,
            "bodies need the implicit coupling");
  SR_ASSERT(krylov_ || !block_preconditioner_, "the direct solve needs a dense mobility");
}

HydroSolveReport HydroCoupling::Prepare(const Model& model, const VecX& q_start,
                                        const VecX& v_start) {
  SR_ASSERT(mobility_ != nullptr, "HydroCoupling::Init was not called");
  positions_.resize(model.rods.size());
  for (int r = 0; r < static_cast<int>(model.rods.size()); ++r)
    positions_[static_cast<size_t>(r)] = RodPositions(model, r, q_start);
  mobility_->UpdateWithBodies(MakeHydroRods(model, positions_), bodies_);
  mobility_changed_ = true;
  ++preconditioner_age_;
  UpdatePreconditionerRotations(model);
  HydroSolveReport report;
  if (!explicit_) return report;
  // The explicit drag: 𝕄 f = −U(t_k).
  VecX u;
  GatherNodeVelocities(model, v_start, VecX::Zero(v_start.size()), 1.0, &u);
  if (const MatX* m = mobility_->matrix()) {
    // The LU of 𝕄 at every step, by LAPACK (solver/dense_lu.h; Eigen's kernels on this build's
    // baseline x86-64 took 80 % of an explicit step). An exactly singular 𝕄 leaves the drag not a
    // number, which the Newton test then reports.
    explicit_force_ = -u;
    if (explicit_lu_.Compute(*m))
      explicit_lu_.Solve(&explicit_force_);
    else
      explicit_force_.setConstant(std::numeric_limits<double>::quiet_NaN());
    return report;
  }
  // The self-mobility blocks change little from step to step: rebuilt every 40 steps.
  if (!explicit_blocks_ || ++explicit_blocks_age_ >= kPreconditionerMaxAge) {
    explicit_blocks_ = std::make_unique<SelfMobilityPreconditioner>(*mobility_);
    explicit_blocks_age_ = 0;
  }
  const LinearOperator apply = [&](const VecX& x, VecX* y) { mobility_->Apply(x, y); };
  const LinearOperator precondition = [&](const VecX& x, VecX* y) {
    explicit_blocks_->Apply(x, y);
  };
  if (explicit_force_.size() != u.size()) explicit_force_.setZero(u.size());
  VecX negative_u = -u;
  // No Newton test checks this drag afterwards, so it is solved tightly (not to krylov_tolerance).
  const GmresReport g = SolveGmres(apply, precondition, negative_u,
                                   {.tolerance = std::min(model.hydro.krylov_tolerance, 1e-10)},
                                   &explicit_force_);
  krylov_total_ += g.iterations;
  report.ok = g.converged;
  report.krylov_iterations = g.iterations;
  report.relative_residual = g.relative_residual;
  return report;
}

void HydroCoupling::SetBodies(const Model& model, const std::vector<BodyPose>& poses) {
  bodies_ = BodySurfaces(model, poses);
  body_velocity_ = BodyPointVelocities(model, poses);
}

void HydroCoupling::ForgetReuse(const VecX& drag_guess) {
  have_preconditioner_ = false;
  preconditioner_h_ = -1.0;
  preconditioner_age_ = 0;
  iterations_after_refresh_ = -1;
  wants_refresh_ = false;
  excess_products_ = 0;
  preconditioner_rotations_ = RodRotations{};
  coarse_rotations_ = RodRotations{};
  coarse_positions_.clear();
  builds_since_coarse_ = 0;
  slowed_severely_ = false;
  mobility_changed_ = true;
  explicit_blocks_.reset();
  explicit_blocks_age_ = 0;
  explicit_force_ = drag_guess;
  if (mobility_) mobility_->AtRestartPoint();
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
  r_u->head(scratch_.size()) += scratch_;
  r_u->segment(3 * model.num_nodes, body_velocity_.size()) += body_velocity_;  // known motion
}

bool HydroCoupling::FactorizeNewtonSystem(const Model& model, double h,
                                          std::vector<BandedMatrix>* jacobian,
                                          std::vector<ClampBorder>* borders) {
  SR_ASSERT(!explicit_, "the capacitance solve is for the implicit coupling");
  const int num_rods = static_cast<int>(jacobian->size());
  std::atomic<bool> regular{true};
  ForEachStatic(num_rods, RodsInParallel(num_rods, model.num_nodes), [&](int r) {
    if (!(*jacobian)[static_cast<size_t>(r)].Factorize())
      regular.store(false, std::memory_order_relaxed);
  });
  if (!regular.load(std::memory_order_relaxed)) return false;
  jacobian_ = jacobian;
  borders_ = borders;
  if (borders) CompleteClampBorders(model, *jacobian, borders);
  // The Krylov preconditioner (O((3M)³) for the full LU) is kept while it serves: rebuilt when
  // GMRES slowed, h changed, or it is kPreconditionerMaxAge steps old. B is always the new one.
  const bool rebuild = !krylov_ || !have_preconditioner_ || wants_refresh_ ||
                       preconditioner_h_ != h ||
                       preconditioner_age_ >= kPreconditionerMaxAge;
  if (rebuild) {
    const bool same_h = preconditioner_h_ == h;  // also that of a kept coarse level
    have_preconditioner_ = true;
    preconditioner_h_ = h;
    preconditioner_age_ = 0;
    iterations_after_refresh_ = -1;
    excess_products_ = 0;
    ++preconditioner_builds_;
    preconditioner_rotations_ = RodRotations{};
    if (rotate_preconditioner_ && krylov_) StartPreconditionerRotations();
    BuildSchurBlocks(model);
    if (block_preconditioner_) {
      std::vector<MatX> blocks(model.rods.size());
      for (std::size_t r = 0; r < model.rods.size(); ++r)
        blocks[r] = h * mobility_->SelfBlock(static_cast<int>(r)) + sx_blocks_[r];
      // The coarse level is kept from an earlier build (in its own frame) for coarse_period_
      // builds, unless h changed or GMRES took more than twice its products after a rebuild.
      const bool keep_coarse = rotate_preconditioner_ && !coarse_positions_.empty() && same_h &&
                               !slowed_severely_ && builds_since_coarse_ + 1 < coarse_period_;
      if (!capacitance_blocks_.Build(model, h, blocks, MakeHydroRods(model, positions_), bodies_,
                                     borders_, true, keep_coarse)) {
        coarse_positions_.clear();  // a failed build's coarse level is not kept
        return have_preconditioner_ = false;
      }
      if (keep_coarse) {
        ++builds_since_coarse_;
        // Prepare turned it already where it was kept before this build too.
        if (coarse_rotations_.empty()) RotationsSince(model, coarse_positions_, &coarse_rotations_);
      } else {
        builds_since_coarse_ = 0;
        coarse_positions_ = preconditioner_positions_;
        coarse_rotations_ = RodRotations{};
        coarse_period_ =
            model.hydro.coarse_rebuild_period > 0
                ? model.hydro.coarse_rebuild_period
                : CoarseRebuildPeriod(capacitance_blocks_.coarse_unknowns(), model.num_nodes);
      }
    } else if (krylov_ && !borders_ && mobility_->single_matrix() != nullptr) {
      // The reused 𝕄 is single precision already: C for the float LU in one pass.
      Eigen::MatrixXf capacitance = static_cast<float>(h) * *mobility_->single_matrix();
      AddSchurBlocks(model, sx_blocks_, &capacitance);
      if (!capacitance_lu_float_.Compute(std::move(capacitance))) return have_preconditioner_ = false;
    } else {
      MatX capacitance = h * *mobility_->matrix();
      AddSchurBlocks(model, sx_blocks_, &capacitance);
      if (borders_) AddClampBordersToCapacitance(model, h, *borders_, &capacitance);
      if (krylov_) {
        if (!capacitance_lu_float_.Compute(capacitance.cast<float>()))
          return have_preconditioner_ = false;
      } else {
        capacitance_lu_.compute(capacitance);
      }
    }
  }
  mobility_changed_ = false;
  wants_refresh_ = false;
  slowed_severely_ = false;
  return true;
}

void HydroCoupling::BuildSchurBlocks(const Model& model) {
  sx_blocks_.resize(model.rods.size());
  const int num_rods = static_cast<int>(model.rods.size());
  // Each rod's own block (and its borders' rows).
  ForEachDynamic(num_rods, num_rods > 1, [&](int ri) {
    const auto r = static_cast<std::size_t>(ri);
    const RodModel& rod = model.rods[r];
    const int n = rod.num_nodes();
    // X_k = B_k⁻¹ S_kᵀ: a unit right-hand side per free position DOF (fixed ones stay zero).
    MatX x = MatX::Zero(rod.num_dofs(), 3 * n);
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        if (!std::binary_search(rod.fixed_dofs.begin(), rod.fixed_dofs.end(), NodeDof(i) + c))
          x(NodeDof(i) + c, 3 * i + c) = 1.0;
    (*jacobian_)[r].Solve(&x);
    MatX& sx = sx_blocks_[r];
    sx.resize(3 * n, 3 * n);
    for (int i = 0; i < n; ++i) sx.middleRows<3>(3 * i) = x.middleRows<3>(NodeDof(i));
    if (borders_)
      for (ClampBorder& border : *borders_)
        if (border.rod == static_cast<int>(r)) border.row_x = border.rows * x;
  });
}

void HydroCoupling::SolveBanded(const Model& model, const VecX& nodal, const VecX* dofs,
                                VecX* out) const {
  // out = B⁻¹ (Sᵀ nodal + dofs): nodal forces on the free position DOFs, plus a DOF vector.
  if (dofs) *out = *dofs; else out->setZero(model.num_dofs);
  for (const RodModel& rod : model.rods) {
    for (int i = 0; i < rod.num_nodes(); ++i)
      out->segment<3>(rod.dof_offset + NodeDof(i)) += nodal.segment<3>(3 * (rod.node_offset + i));
    for (int k : rod.fixed_dofs) (*out)(rod.dof_offset + k) = dofs ? (*dofs)(rod.dof_offset + k) : 0.0;
  }
  SolveRodsBanded(model, *jacobian_, out);
}

void HydroCoupling::ApplyCapacitance(const Model& model, double h, const VecX& v,
                                     VecX* out) const {
  // C v = h 𝕄 v + S B⁻¹ Sᵀ v: the elastic part by a banded solve per rod (O(N), no dense S X).
  mobility_->Apply(v, out);
  *out *= h;
  SolveBanded(model, v, nullptr, &scratch_dofs_);
  for (const RodModel& rod : model.rods)
    for (int i = 0; i < rod.num_nodes(); ++i)
      out->segment<3>(3 * (rod.node_offset + i)) += scratch_dofs_.segment<3>(rod.dof_offset + NodeDof(i));
  if (borders_) ApplyClampBorders(model, h, *borders_, v, scratch_dofs_, out);
}

void HydroCoupling::StartPreconditionerRotations() {
  // The rods' nodes about their centroids at the build; the rotations (and where each rod's
  // entries sit) come with the next Prepare (none until then: built where it stands).
  const std::size_t num_rods = positions_.size();
  preconditioner_positions_.resize(num_rods);
  for (std::size_t r = 0; r < num_rods; ++r)
    preconditioner_positions_[r] = positions_[r].colwise() - positions_[r].rowwise().mean();
}

void HydroCoupling::UpdatePreconditionerRotations(const Model& model) {
  if (!rotate_preconditioner_ || !have_preconditioner_ ||
      preconditioner_positions_.size() != positions_.size())
    return;
  RotationsSince(model, preconditioner_positions_, &preconditioner_rotations_);
  if (capacitance_blocks_.coarse_kept() && coarse_positions_.size() == positions_.size())
    RotationsSince(model, coarse_positions_, &coarse_rotations_);
  else
    coarse_rotations_ = RodRotations{};
}

void HydroCoupling::RotationsSince(const Model& model, const std::vector<Matrix3X>& built,
                                   RodRotations* q) const {
  const int num_rods = static_cast<int>(positions_.size());
  q->rotation.resize(positions_.size());
  q->first_node.resize(positions_.size());
  q->nodes.resize(positions_.size());
  ForEachStatic(num_rods, RodsInParallel(num_rods, model.num_nodes), [&](int ri) {
    const auto r = static_cast<std::size_t>(ri);
    q->first_node[r] = model.rods[r].node_offset;
    q->nodes[r] = model.rods[r].num_nodes();
    q->rotation[r] = Mat3::Identity();
    // A rod clamped on a body turns with it; its cell's block holds the body's points, which
    // stay as built: the rod's block is applied as built too.
    if (model.rods[r].body >= 0) return;
    // Kabsch: the rotation R maximizing Σ (x_i − x̄)ᵀ R (x⁰_i − x̄⁰) is U diag(1, 1, ±1) Vᵀ
    // from the SVD U Σ Vᵀ of Σ (x_i − x̄)(x⁰_i − x̄⁰)ᵀ, the sign making det R = +1.
    const Matrix3X& now = positions_[r];
    const Mat3 covariance = (now.colwise() - now.rowwise().mean()) * built[r].transpose();
    const Eigen::JacobiSVD<Mat3> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Mat3 sign = Mat3::Identity();
    if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) sign(2, 2) = -1.0;
    q->rotation[r] = svd.matrixU() * sign * svd.matrixV().transpose();
  });
}

void RodRotations::Apply(bool transpose, VecX* x) const {
  for (std::size_t r = 0; r < rotation.size(); ++r) {
    const Mat3 q = transpose ? Mat3(rotation[r].transpose()) : rotation[r];
    for (int i = first_node[r]; i < first_node[r] + nodes[r]; ++i) {
      const Vec3 turned = q * x->segment<3>(3 * i);
      x->segment<3>(3 * i) = turned;
    }
  }
}

void HydroCoupling::Precondition(const VecX& v, VecX* out) const {
  if (block_preconditioner_)  // Q P₀ Qᵀ v, each level in its own frame
    return capacitance_blocks_.Apply(v, out, preconditioner_rotations_, coarse_rotations_);
  const RodRotations& q = preconditioner_rotations_;
  const VecX* in = &v;
  if (!q.empty()) {  // Q P₀ Qᵀ v
    scratch_ = v;
    q.Apply(true, &scratch_);
    in = &scratch_;
  }
  Eigen::VectorXf x = in->cast<float>();
  capacitance_lu_float_.Solve(&x);
  *out = x.cast<double>();
  if (!q.empty()) q.Apply(false, out);
}

HydroSolveReport HydroCoupling::SolveNewtonSystem(const Model& model,
                                                  const std::vector<BandedMatrix>& jacobian,
                                                  double h, const VecX& r_q, const VecX& r_u,
                                                  VecX* dq, VecX* df, VecX* du,
                                                  double velocity_tolerance) {
  HydroSolveReport report;
  // y = −B⁻¹ r_q, and S y.
  *dq = -r_q;
  VecX sy = VecX::Zero(mobility_->size());  // zero on the bodies' points (no S there)
  SolveRodsBanded(model, jacobian, dq);
  for (const RodModel& rod : model.rods)
    for (int i = 0; i < rod.num_nodes(); ++i)
      sy.segment<3>(3 * (rod.node_offset + i)) = dq->segment<3>(rod.dof_offset + NodeDof(i));
  for (const RodModel& rod : model.rods)  // S selects free DOFs only (X has zero fixed rows)
    for (int k : rod.fixed_dofs)
      if (k % 4 != 3) sy(3 * rod.node_offset + 3 * (k / 4) + k % 4) = 0.0;
  if (borders_) AddClampBorderRhs(model, h, *borders_, *dq, &sy);
  const VecX b = -(h * r_u + sy);
  VecX cdf;   // C δf
  VecX x_df;  // X δf = B⁻¹ Sᵀ δf, when the Krylov solve gives it (else solved for below)
  if (!krylov_) {
    SR_ASSERT(!mobility_changed_, "the direct solve needs the capacitance of the current 𝕄");
    *df = capacitance_lu_.solve(b);
    ApplyCapacitance(model, h, *df, &cdf);
    report.relative_residual = (b - cdf).norm() / std::max(b.norm(), 1e-300);
  } else {
    // Each product solves for X v = B⁻¹ Sᵀ v (ApplyCapacitance): GMRES combines them into X δf.
    const LinearOperatorWithSide apply = [&](const VecX& x, VecX* y, VecX* xv) {
      ApplyCapacitance(model, h, x, y);
      if (xv) *xv = scratch_dofs_;
    };
    const LinearOperator precondition = [&](const VecX& x, VecX* y) { Precondition(x, y); };
    df->setZero(b.size());
    // r_u after the step is −(b − C δf)/h, and the Newton test reads its largest component:
    // GMRES stops on that, not on the 2-norm (up to √(3M) times larger for a residual spread
    // over M nodes: on 100 helices 25–45 times, so it solved to 2–4 % of what the test asks).
    const GmresReport g = SolveGmres(apply, precondition, b,
                                     {.tolerance = model.hydro.krylov_tolerance,
                                      .absolute_tolerance = h * velocity_tolerance,
                                      .absolute_in_max_norm = true},
                                     df, &cdf, &x_df);
    report.ok = g.converged;
    report.krylov_iterations = g.iterations;
    report.relative_residual = g.relative_residual;
    krylov_total_ += g.iterations;
    if (!g.converged && (worst_solve_.ok || g.relative_residual > worst_solve_.relative_residual))
      worst_solve_ = report;
    if (iterations_after_refresh_ < 0) iterations_after_refresh_ = g.iterations;
    excess_products_ += std::max(0, g.iterations - iterations_after_refresh_);
    slowed_severely_ = g.iterations > 2 * iterations_after_refresh_ + 2;
    wants_refresh_ =
        slowed_severely_ || excess_products_ >= (block_preconditioner_ ? kBlockRebuildCostInProducts
                                                                       : kRebuildCostInProducts);
  }
  // δq = y + X δf = y + B⁻¹ Sᵀ δf;  du = S δq/h + 𝕄 δf = (S y + C δf)/h.
  if (x_df.size() == 0) SolveBanded(model, *df, nullptr, &x_df);  // direct, or δf = 0
  *dq += x_df;
  if (borders_) AddClampMotion(model, h, *borders_, *df, dq);
  *du = (sy + cdf) / h;
  return report;
}

}  // namespace stokesrods
