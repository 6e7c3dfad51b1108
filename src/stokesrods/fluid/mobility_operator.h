// The fluid as a linear operator: U = 𝕄 F over all hydrodynamic nodes (paper eq. 21), applied
// without necessarily forming 𝕄.
//
// Every consumer of the hydrodynamics (the implicit step, the explicit drag, the flow field)
// needs only three things: the geometry at which 𝕄 is taken (Update), products U = 𝕄 F (Apply),
// and, to precondition its solves, the self-mobility of each rod (SelfBlock). Two
// implementations:
//   dense      : 𝕄 assembled in full (fluid/hydrodynamics.h), Apply a matrix–vector product. The
//                reference; O(M²) memory and assembly. All models (RSS, LSBT, RFT).
//   matrix-free: RSS only. Each segment–node interaction is either "near" (δ = √(d² + ε²)/L below
//                a bound set by the tolerance), integrated exactly by the closed forms of
//                stokeslet_segment.h and stored as 3×3 blocks, or "far", integrated by a
//                Gauss–Legendre rule whose point Stokeslets are summed by a fast summation
//                (stokeslet_sum.h). O(M) memory.
// Further sources of flow extend the node set and the kernel behind the same interface: a wall's
// images are in the kernel (FluidParams::wall, dense; matrix-free: fluid/wall_sources.h), cell
// bodies' surface points follow the rods' nodes in F and U (UpdateWithBodies; dense, or the
// matrix-free operator wrapped by fluid/mobility_sources.h).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/LU>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/hydrodynamics.h"
#include "stokesrods/fluid/mobility_reuse.h"
#include "stokesrods/fluid/rigid_body.h"
#include "stokesrods/fluid/stokeslet_sum.h"

namespace stokesrods {

enum class MobilityKind { kDense, kMatrixFree };

/// Near corrections of the matrix-free RSS at a set of targets: target t takes
/// Σ_k block[k] F_{source[k]}, k ∈ [start[t], start[t + 1]), F the nodal forces: for each rod
/// segment near t (δ below the split's near radius), its closed forms minus the far rule, per node.
/// The blocks are kept in single precision (block_single) where the operator's far field is
/// summed in single precision (fast_sum_tolerance ≥ kSinglePrecisionTolerance): their rounding,
/// 6e-8 relative, is far below that sum's; each product streams a third of the bytes of a double
/// 3 × 3 block (on 100 helices 138 000 blocks, read by every product), summed in double. In single
/// precision a block keeps its six distinct entries: the RSS near blocks are symmetric (a
/// regularized Stokeslet's tensor integrated against a hat function, times 1/Λ: PackNearBlocks
/// checks it), and the product reads each off-diagonal entry for both of its places, as a full
/// block's product would (the same sums).
struct NearBlocks {
  /// A symmetric block's entries (0,0), (1,0), (2,0), (1,1), (2,1), (2,2).
  using SymmetricBlock = std::array<float, 6>;
  std::vector<int> start = {0}, source;
  std::vector<Mat3> block;                    ///< in double, unless single
  std::vector<SymmetricBlock> block_single;   ///< in single precision, if single
  bool single = false;
  std::size_t size() const { return source.size(); }
  /// The correction at target t for the nodal forces F (3M).
  Vec3 At(int t, const VecX& force) const {
    Vec3 u = Vec3::Zero();
    const int begin = start[static_cast<size_t>(t)], end = start[static_cast<size_t>(t) + 1];
    if (single) {  // written out: Eigen's mixed product goes through a temporary and a loop
      double ux = 0.0, uy = 0.0, uz = 0.0;
      for (int k = begin; k < end; ++k) {
        const float* b = block_single[static_cast<size_t>(k)].data();
        const double* f = force.data() + 3 * source[static_cast<size_t>(k)];
        ux += double(b[0]) * f[0] + double(b[1]) * f[1] + double(b[2]) * f[2];
        uy += double(b[1]) * f[0] + double(b[3]) * f[1] + double(b[4]) * f[2];
        uz += double(b[2]) * f[0] + double(b[4]) * f[1] + double(b[5]) * f[2];
      }
      u = Vec3(ux, uy, uz);
    } else {
      for (int k = begin; k < end; ++k)
        u += block[static_cast<size_t>(k)] * force.segment<3>(3 * source[static_cast<size_t>(k)]);
    }
    return u;
  }
};

/// What one product of a matrix-free operator costs (of its last Update): the near corrections'
/// 3×3 blocks and the far-field sum's estimated cost in kernel evaluations (StokesletSumStats).
struct MobilityCostCounts {
  std::int64_t near_blocks = 0;
  double far_sum_cost = 0.0;
  int gauss_points = 0;
};

struct MobilityOptions {
  MobilityKind kind = MobilityKind::kDense;
  /// Matrix-free: bound on the relative error of each far segment–node interaction (quadrature).
  /// The far field as a whole is accurate to max(tolerance, fast_sum_tolerance) at every size
  /// (the quadrature need not be finer than the sum it feeds) [–].
  double tolerance = 1e-8;
  /// Matrix-free: the far-field sum runs directly below this many source–target pairs (in single
  /// precision from fast_sum_tolerance 1e-4); above, the FMM decides by its cost model.
  double direct_sum_below = 4e6;
  /// Matrix-free: the bound on the error of the far-field sum, relative per node to Σ |S||g|
  /// over the Gauss points (stokeslet_sum.h); it sets the FMM's expansion order (fmm_sum.cc) and
  /// the direct sum's precision [–].
  double fast_sum_tolerance = 1e-4;
  /// Matrix-free: false uses the FMM whenever the geometry allows it, paying or not (tests).
  bool fast_sum_by_cost = true;
  /// Matrix-free: the largest near radius (segment lengths) for the split, which takes
  /// max(tolerance, fast_sum_tolerance) as the quadrature's tolerance [–].
  double fast_sum_near_delta = 12.0;
  /// Matrix-free: at the first Update and every restart point (ForgetHistory), the split with one
  /// more Gauss point (and its smaller near zone) replaces that one where the estimated cost of a
  /// step is lower (mobility_operator.cc); false keeps ChooseNearFarSplit's (tests) [–].
  bool split_by_cost = true;
  /// Matrix-free, where the far sum is direct and the split takes more than 2 Gauss points: each
  /// rod far enough from a group of targets is summed there with fewer points, as few as meet the
  /// same tolerance at that distance (fluid/far_rule_sum.h); false: the split's points on every
  /// rod (tests, the reference) [–].
  bool far_rule_by_distance = true;
  /// Matrix-free, where the far rule by distance serves: the nodes' near pairs are left out of
  /// the far sum and their near corrections are the closed forms alone, instead of the sum adding
  /// the rule there and the corrections taking it back (fluid/far_rule_sum.h); false: the latter
  /// (tests, the reference) [–].
  bool exclude_near_from_far_sum = true;
  /// Dense: 𝕄 reused across Updates (time steps) by extrapolation while its measured relative
  /// error stays below this (fluid/mobility_reuse.h); 0 assembles at every Update. From
  /// kSinglePrecisionTolerance on, the products take 𝕄 in single precision also where it was
  /// assembled (sums in double, solver/blas.h GemvRowsMixed) [–].
  double reuse_tolerance = 0.0;
};

class MobilityOperator {
 public:
  virtual ~MobilityOperator() = default;
  /// Takes the geometry: 𝕄 = 𝕄(x) for the rods as they are now.
  virtual void Update(const std::vector<HydroRod>& rods) = 0;
  /// The same with the bodies' surfaces (fluid/rigid_body.h), their P points after the rods' M
  /// nodes in F and U, then the free bodies' rigid motions (AssembleBorderedMobility): size() is
  /// 3(M + P) + 6B. Operators without bodies take an empty list only.
  virtual void UpdateWithBodies(const std::vector<HydroRod>& rods,
                                const std::vector<BodySurface>& bodies) {
    SR_ASSERT(bodies.empty(), "this mobility operator does not take bodies");
    Update(rods);
  }
  /// U = 𝕄 F (3M each) at the geometry of the last Update.
  virtual void Apply(const VecX& force, VecX* velocity) const = 0;
  /// The block of 𝕄 coupling rod k's nodes to themselves (3N_k × 3N_k), exact.
  virtual MatX SelfBlock(int rod) const = 0;
  /// The assembled 𝕄 when the operator holds one, else nullptr.
  virtual const MatX* matrix() const { return nullptr; }
  /// 𝕄 in single precision when the products take it so (the dense 𝕄 extrapolated by its reuse,
  /// fluid/mobility_reuse.h, or assembled and rounded at a reuse tolerance ≥
  /// kSinglePrecisionTolerance), else nullptr: for what reads it in single precision anyway.
  virtual const Eigen::MatrixXf* single_matrix() const { return nullptr; }
  /// Forgets what the operator keeps from earlier Updates: the next Update then depends on its
  /// geometry alone.
  virtual void ForgetHistory() {}
  /// A restart point (io/runner.h): forgets what reuse_history() does not keep, so that the next
  /// Updates depend on the geometry and that history alone (matrix-free: the split is chosen
  /// again; dense: nothing is forgotten).
  virtual void AtRestartPoint() { ForgetHistory(); }
  /// The dense 𝕄's reuse history (fluid/mobility_reuse.h) as a checkpoint keeps it; empty for
  /// the other operators.
  virtual MobilityReuseHistory reuse_history() const { return {}; }
  /// Takes back a history of reuse_history(): the next Update assembles 𝕄 at its geometries
  /// again and goes on as the operator it was taken from.
  virtual void RestoreReuse(const MobilityReuseHistory& /*history*/) {}
  /// Reuse of 𝕄 across Updates, counted since the operator was made.
  virtual MobilityReuseStats reuse_stats() const { return {}; }
  /// Matrix-free: the work of one product at the last Update (zeros for the dense operator).
  virtual MobilityCostCounts cost_counts() const { return {}; }
  /// Matrix-free RSS: the near corrections of the rods (of the last Update) at any targets, as
  /// the operator applies them at its own nodes (cell bodies' points: fluid/mobility_sources.h).
  virtual void FindNearBlocks(const Matrix3X& /*targets*/, NearBlocks* /*blocks*/) const {
    SR_ASSERT(false, "near blocks belong to the matrix-free operator");
  }

  int size() const { return 3 * (node_offset_.back() + num_body_points_) + 6 * num_free_bodies_; }
  int num_rods() const { return static_cast<int>(node_offset_.size()) - 1; }
  /// First node of rod k among all nodes; node_offset(num_rods()) = M.
  int node_offset(int rod) const { return node_offset_[static_cast<size_t>(rod)]; }

 protected:
  void SetLayout(const std::vector<HydroRod>& rods);
  std::vector<int> node_offset_ = {0};
  int num_body_points_ = 0;  ///< P (UpdateWithBodies)
  int num_free_bodies_ = 0;  ///< B (UpdateWithBodies)
};

/// Block-Jacobi approximation of 𝕄⁻¹ by the LU of each rod's self-mobility 𝕄_kk: the
/// preconditioner of the solves 𝕄 F = U (explicit drag, flow field) with a matrix-free 𝕄.
class SelfMobilityPreconditioner {
 public:
  /// Factorizes the self blocks of the operator at its current geometry.
  explicit SelfMobilityPreconditioner(const MobilityOperator& mobility);
  /// out ≈ 𝕄⁻¹ in, rod by rod.
  void Apply(const VecX& in, VecX* out) const;

 private:
  std::vector<int> first_;  ///< first entry (3 × node) of each rod; back() = 3M
  std::vector<Eigen::PartialPivLU<MatX>> blocks_;
};

/// The operator for the fluid model and options (matrix-free needs RSS; others fall back to dense).
std::unique_ptr<MobilityOperator> MakeMobilityOperator(const FluidParams& params,
                                                       const MobilityOptions& options);

/// Near/far split of the matrix-free RSS: the far rule's number of Gauss points per segment and
/// the δ = √(d² + ε²)/L below which a segment–node pair is integrated exactly, for a tolerance.
struct NearFarSplit {
  int gauss_points = 3;
  double near_delta = 0.0;
};
/// The fewest points whose near radius is at most `max_near_delta` segment lengths.
NearFarSplit ChooseNearFarSplit(double tolerance, double max_near_delta = 12.0);
/// The near radius δ_n (segment lengths) of the n-point rule at a tolerance.
double NearRadius(int gauss_points, double tolerance);

}  // namespace stokesrods
