// Thrust, torque and drag of a rigid helix (no elasticity: the motion is prescribed) with each
// hydrodynamic model, in the dimensionless form of Rodenborn et al. (PNAS 2013, Fig. 2):
//   thrust / (η ω R²) of a helix rotating at ω about its axis, held from translating;
//   torque / (η ω R³) of the same motion; drag / (η U R) of the helix translating along its axis.
// Usage: rigid_helix LAMBDA_OVER_R...  (prints CSV; scripts/studies/rodenborn.py plots it)
// Geometry (the experiment's): R = 6.3 mm, filament radius a = 0.397 mm, axial length 130 mm.
#include <Eigen/LU>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "stokesrods/fluid/hydrodynamics.h"
#include "stokesrods/fluid/lsbt.h"
#include "stokesrods/fluid/rft.h"

namespace {

using namespace stokesrods;

constexpr double kHelixRadius = 6.3e-3;    // R [m]
constexpr double kFilamentRadius = 0.397e-3;  // a [m]
constexpr double kAxialLength = 0.130;     // [m]

// Nodes on the helix x = R cos φ, y = R sin φ, z = −λφ/2π, evenly spaced in arc length, with
// edges as close to `edge` as a whole number of them allows.
Matrix3X Helix(double pitch, double edge) {
  const double turns = kAxialLength / pitch;
  const double arc = turns * std::hypot(pitch, 2.0 * kPi * kHelixRadius);
  const int edges = std::max(4, static_cast<int>(std::lround(arc / edge)));
  Matrix3X x(3, edges + 1);
  for (int i = 0; i <= edges; ++i) {
    const double phi = 2.0 * kPi * turns * i / edges;
    x.col(i) = Vec3(kHelixRadius * std::cos(phi), kHelixRadius * std::sin(phi), -pitch * phi / (2.0 * kPi));
  }
  return x;
}

struct Coefficients {
  double thrust, torque, drag;
  long nodes;
};

Coefficients Solve(const FluidParams& params, const HydroRod& rod) {
  const Matrix3X& x = *rod.x;
  MatX m;
  AssembleMobility(params, {rod}, &m);
  const Eigen::PartialPivLU<MatX> lu(m);
  const Eigen::Index n = x.cols();
  VecX spin(3 * n), slide(3 * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    spin.segment<3>(3 * i) = Vec3::UnitZ().cross(Vec3(x.col(i)));  // ω = 1 rad/s
    slide.segment<3>(3 * i) = Vec3::UnitZ();                        // U = 1 m/s
  }
  const VecX f_spin = lu.solve(spin), f_slide = lu.solve(slide);
  Vec3 force = Vec3::Zero(), torque = Vec3::Zero(), drag = Vec3::Zero();
  for (Eigen::Index i = 0; i < n; ++i) {
    force += f_spin.segment<3>(3 * i);
    torque += Vec3(x.col(i)).cross(Vec3(f_spin.segment<3>(3 * i)));
    drag += f_slide.segment<3>(3 * i);
  }
  const double eta = params.viscosity, r = kHelixRadius;
  return {std::abs(force.z()) / (eta * r * r), std::abs(torque.z()) / (eta * r * r * r),
          std::abs(drag.z()) / (eta * r), static_cast<long>(n)};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    fmt::print(stderr, "usage: rigid_helix LAMBDA_OVER_R...\n");
    return 2;
  }
  fmt::print("model,lambda_over_R,nodes,thrust_over_eta_omega_R2,torque_over_eta_omega_R3,drag_over_eta_U_R\n");
  for (int k = 1; k < argc; ++k) {
    const double pitch = std::strtod(argv[k], nullptr) * kHelixRadius;
    struct Variant {
      std::string name;
      FluidModel model;
      double regularization;  // ε / a (RSS)
      double edge;            // target edge length [m]
    };
    // RSS at the paper's Δl/r0 ≈ 5; LSBT at its required edge a√e; RFT with Lighthill's coefficients.
    const std::vector<Variant> variants = {
        {"rss_eps1.02", FluidModel::kRss, 1.02, 5.0 * kFilamentRadius},
        {"rss_eps_sqrt_e", FluidModel::kRss, std::sqrt(std::exp(1.0)), 5.0 * kFilamentRadius},
        {"lsbt", FluidModel::kLsbt, 1.02, LsbtEdgeLength(kFilamentRadius)},
        {"rft_lighthill", FluidModel::kRft, 1.02, 5.0 * kFilamentRadius}};
    for (const Variant& v : variants) {
      const Matrix3X x = Helix(pitch, v.edge);
      FluidParams params;
      params.model = v.model;
      params.regularization = v.regularization;
      HydroRod rod{&x, kFilamentRadius};
      if (v.model == FluidModel::kRft) {
        const RftCoefficients c = LighthillCoefficients(params.viscosity, kFilamentRadius,
                                                        std::hypot(pitch, 2.0 * kPi * kHelixRadius));
        rod.rft_parallel = c.parallel;
        rod.rft_perpendicular = c.perpendicular;
      }
      const Coefficients c = Solve(params, rod);
      fmt::print("{},{:.6g},{},{:.4f},{:.4f},{:.4f}\n", v.name, pitch / kHelixRadius, c.nodes,
                 c.thrust, c.torque, c.drag);
    }
  }
  return 0;
}
