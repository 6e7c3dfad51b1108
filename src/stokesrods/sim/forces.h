// External forces that act locally (on each node separately) with their Jacobians: the single
// interface through which loads, gravity, damping and local drag enter the implicit step.
// Nonlocal hydrodynamics couples all nodes and has its own unit (hydro_coupling.h); contact
// forces are constant during a Newton solve (contact_forces.h).
#pragma once

#include <memory>
#include <vector>

#include "stokesrods/sim/model.h"
#include "stokesrods/solver/banded_matrix.h"

namespace stokesrods {

/// What a force sees during one implicit step: the start of the step and the step size.
struct StepContext {
  const VecX* q_start = nullptr;  ///< q(t_k)
  double time_step = 0.0;         ///< h [s]; 0 in a static solve (velocity-dependent forces vanish)
  double load_factor = 1.0;       ///< scales the constant loads (static load continuation)
};

class ExternalForce {
 public:
  virtual ~ExternalForce() = default;
  /// Called once at the start of each step (caches what depends on q(t_k) only).
  virtual void Prepare(const Model& /*model*/, const VecX& /*q_start*/) {}
  /// Adds the force at the trial DOFs q (velocity (q − q_k)/h) into the global `force`, and
  /// −∂F/∂q into the per-rod banded matrices `jacobian` (local indices) when not null.
  virtual void AddTo(const Model& model, const StepContext& ctx, const VecX& q, VecX* force,
                     std::vector<BandedMatrix>* jacobian) const = 0;
};

/// Point loads and gravity: F_i = λ (P_i + m_i g), constant.
class ConstantLoads final : public ExternalForce {
 public:
  void AddTo(const Model& model, const StepContext& ctx, const VecX& q, VecX* force,
             std::vector<BandedMatrix>* jacobian) const override;
};

/// Local viscous drag F_i = −Δl_i C_i u_i with u_i = (x_i − x_i(t_k))/h and the 3 × 3 resistance
/// per unit length C_i = c_∥ t tᵀ + c_⊥ (I − t tᵀ) (t the node's tangent at the start of the
/// step). Isotropic damping is c_∥ = c_⊥; resistive force theory is the anisotropic case.
class LocalDrag final : public ExternalForce {
 public:
  /// Coefficients per rod (c_∥, c_⊥) [Pa·s].
  explicit LocalDrag(std::vector<Vec2> coefficients) : coefficients_(std::move(coefficients)) {}
  void Prepare(const Model& model, const VecX& q_start) override {
    CalcResistance(model, q_start, &blocks_);
  }
  void AddTo(const Model& model, const StepContext& ctx, const VecX& q, VecX* force,
             std::vector<BandedMatrix>* jacobian) const override;
  /// The resistance blocks Δl_i C_i of every node (3M × 3 stacked), as used for q_start.
  void CalcResistance(const Model& model, const VecX& q_start, Eigen::MatrixX3d* blocks) const;

 private:
  std::vector<Vec2> coefficients_;
  Eigen::MatrixX3d blocks_;  ///< Δl_i C_i at q(t_k), 3M × 3
};

/// The local external forces of a model (loads, gravity, damping, RFT drag).
std::vector<std::unique_ptr<ExternalForce>> MakeLocalForces(const Model& model);

}  // namespace stokesrods
