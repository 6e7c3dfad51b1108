// The constant description of a simulation (MuJoCo's mjModel): rods, materials, rest shapes,
// boundary conditions, loads and the force models. Built once from the configuration (see
// io/build_model.h); never changed by a step.
#pragma once

#include <string>
#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/hydrodynamics.h"
#include "stokesrods/fluid/mobility_operator.h"

namespace stokesrods {

/// DOF layout of one rod (paper section 2.1): q = [x0, θ0, x1, θ1, …, θ_{N−2}, x_{N−1}], 4N − 1.
inline int NodeDof(int node) { return 4 * node; }
inline int TwistDof(int edge) { return 4 * edge + 3; }
inline int RodDofCount(int nodes) { return 4 * nodes - 1; }

struct PointLoad {
  int node = 0;
  Vec3 force = Vec3::Zero();  ///< [N]
};

struct RodModel {
  // Material and cross section.
  double radius = 0.0;              ///< r0 [m]
  double density = 0.0;             ///< ρ [kg/m³]
  double axial_stiffness = 0.0;     ///< EA [N]
  double bending_stiffness = 0.0;   ///< EI = E π r0⁴/4 [N·m²]
  double twisting_stiffness = 0.0;  ///< GJ, G = E/(2(1+ν)), J = π r0⁴/2 [N·m²]

  // Rest shape (stress-free), from which the rest strains are measured.
  Matrix3X rest_positions;      ///< 3 × N [m]
  VecX rest_edge_length;        ///< |ē^i|, N − 1 [m]
  VecX rest_voronoi_length;     ///< Δl_i = (|ē^{i−1}| + |ē^i|)/2, ends: half an edge, N [m]
  std::vector<Vec2> rest_curvature;  ///< (κ̄⁽¹⁾, κ̄⁽²⁾) per node (interior nodes used), N
  VecX rest_twist;              ///< τ̄ per node (interior nodes used), N [rad]
  VecX mass;                    ///< lumped mass per DOF, 4N − 1: ρAΔl_i on x_i, ρJ|ē^j| on θ^j

  // Boundary conditions.
  int clamped_nodes = 0;        ///< 0, 1 or 2 leading nodes held fixed (2 also holds θ0)
  double twist_rate = 0.0;      ///< dθ0/dt [rad/s] imposed when clamped_nodes == 2
  double omega = 0.0;           ///< rotation rate about +ẑ as configured [rad/s]
  /// The body (model index) that holds the clamp and against which θ0 turns; −1: none (fixed in
  /// space). A prescribed body carries the clamped nodes and θ0 with it (sim/bodies.h).
  int body = -1;
  std::vector<int> fixed_dofs;  ///< local DOFs held at their current value, sorted
  std::vector<PointLoad> loads;

  // Resistive force theory coefficients (c_∥, c_⊥) per unit length [Pa·s], fluid.model = rft.
  Vec2 rft_coefficients = Vec2::Zero();

  // Descriptive geometry (for observables).
  double axis_length = 0.0;     ///< l0 [m]
  double helix_radius = 0.0;    ///< R [m] (0 when not a helix)

  // Place in the global vectors.
  int dof_offset = 0;           ///< first index of this rod in the global q
  int node_offset = 0;          ///< first node of this rod among all nodes (fluid, contact)

  int num_nodes() const { return static_cast<int>(rest_positions.cols()); }
  int num_dofs() const { return RodDofCount(num_nodes()); }
};

/// A rigid cell body (issue 11): its surface as regularized Stokeslets (fluid/rigid_body.h),
/// more sources and targets of the mobility beside the rods' nodes. Its motion is "fixed",
/// "prescribed" (constant U and Ω) or "free" (U and Ω unknowns of the step, with the balance of
/// the fluid's force and torque on it; sim/hydro_coupling.h).
enum class BodyMotion { kFixed, kPrescribed, kFree };

struct BodyModel {
  double radius = 0.0;                     ///< a [m]
  Vec3 center = Vec3::Zero();              ///< at t = 0 [m]
  BodyMotion motion = BodyMotion::kFixed;
  Vec3 velocity = Vec3::Zero();            ///< U [m/s]
  Vec3 angular_velocity = Vec3::Zero();    ///< Ω about the centre [rad/s]
  Vec3 force = Vec3::Zero();               ///< a free body's own load (e.g. weight − buoyancy) [N]
  Vec3 torque = Vec3::Zero();              ///< and torque about its centre [N·m]
  Matrix3X surface;                        ///< surface points relative to the centre at t = 0 [m]
  double regularization = 0.0;             ///< ε of the surface blobs [m]
  int point_offset = 0;                    ///< first of its points after all rods' nodes
  int free_index = -1;                     ///< among the free bodies (their (U, Ω) unknowns)

  int num_points() const { return static_cast<int>(surface.cols()); }
};

enum class FluidCoupling { kImplicit, kExplicit };
/// kEuler: implicit Euler (paper eq. 22), first order. kBdf2: the two-step backward
/// differentiation formula, second order (its first step is implicit Euler).
enum class TimeIntegrator { kEuler, kBdf2 };

struct NewtonOptions {
  double tolerance = 1e-8;     ///< on the residual force, relative to the force scale [–]
  int max_iterations = 30;
  int max_contact_rounds = 50; ///< Algorithm 1: solve–detect–re-solve rounds per step
  double contact_tolerance = 1e-3;  ///< a pair is resolved when distance ≥ 2r0 (1 − this)
  /// Steps a factorized Newton matrix may be reused for (0: rebuild at every iteration).
  int jacobian_max_age = 1;
};

/// How the capacitance C = h𝕄 + S X of the implicit coupling is solved (sim/hydro_coupling.h).
enum class HydroSolver { kDirect, kKrylov };

struct HydroOptions {
  MobilityOptions mobility;                    ///< dense or matrix-free 𝕄
  HydroSolver solver = HydroSolver::kKrylov;
  double krylov_tolerance = 1e-6;              ///< GMRES: |b − C x| ≤ this × |b|  [–]
  /// GMRES: the kept preconditioner follows each rod's rotation since it was built
  /// (sim/hydro_coupling.h); false applies it as built (the reference).
  bool rotate_preconditioner = true;
  /// Matrix-free: the coarse level is rebuilt at every this-many rebuilds of the preconditioner
  /// (kept in its own frame between them, with rotate_preconditioner); 0: by its cost
  /// (CoarseRebuildPeriod, sim/hydro_coupling.h).
  int coarse_rebuild_period = 0;
};

struct Model {
  std::vector<RodModel> rods;
  std::vector<BodyModel> bodies;     ///< their points follow the rods' nodes in the drag vector
  FluidParams fluid;                 ///< fluid.model == kNone: no hydrodynamics
  FluidCoupling coupling = FluidCoupling::kImplicit;
  TimeIntegrator integrator = TimeIntegrator::kEuler;
  HydroOptions hydro;
  bool contact = false;
  Vec3 gravity = Vec3::Zero();       ///< [m/s²]
  double damping = 0.0;              ///< local viscous damping per unit length [Pa·s] (validation)
  NewtonOptions newton;
  double force_scale = 0.0;          ///< characteristic force max EI/L² over rods [N]
  double length_scale = 0.0;         ///< longest rod arc length [m]
  double max_voronoi_length = 0.0;   ///< largest rest Voronoi length Δl_i over all nodes [m]

  int num_dofs = 0;
  int num_nodes = 0;
  int num_body_points = 0;           ///< P
  int num_free_bodies = 0;           ///< B: the drag vector has 3(M + P) + 6B entries

  int num_hydro_points() const { return num_nodes + num_body_points; }
  /// Entries of the implicit coupling's hydrodynamic unknown: the forces at the rods' nodes and
  /// the bodies' points, then (U, Ω) of each free body.
  int hydro_size() const { return 3 * num_hydro_points() + 6 * num_free_bodies; }
};

/// Fills dof_offset/node_offset, num_dofs/num_nodes, force_scale and length_scale from the rods,
/// the bodies' point_offset and num_body_points.
void FinalizeLayout(Model* model);

/// Fills the rest quantities (lengths, Voronoi lengths, masses, rest curvatures and twist from
/// space-parallel frames of the rest shape) and the DOFs fixed by clamped_nodes. The rod's
/// radius, density, stiffnesses, rest_positions and clamped_nodes must be set.
void FinalizeRod(RodModel* rod);

}  // namespace stokesrods
