// Cell bodies behind the matrix-free mobility (fluid/mobility_sources.h) in whole runs, with the
// capacitance preconditioned by blocks bordered by the free bodies' motions
// (sim/capacitance_preconditioner.h), against the dense reference (dense 𝕄 with the bodies, the
// capacitance by a fresh LU at every step): a swimming cell (a free sphere holding two helices,
// their motors turning them against it) beside a fixed sphere, 4 steps of implicit Euler
// (tests/common/cell_toml.h).
// All paths solve the same discrete equations; the fast ones stop GMRES at the Newton tolerance,
// and the matrix-free one carries its far-field tolerance. As tests/validation/fast_path_test.cc:
// at a far field of 1e-8 we allow 1e-6 (of the helix radius on positions, of their largest values
// on the body's U, Ω and the fluid's force on it); at the default far field with bodies (1e-5, the
// sum in double: io/build_model.cc), 1e-5. Every GMRES solve must reach its tolerance.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "common/cell_toml.h"
#include "common/model_from_toml.h"
#include "stokesrods/sim/bodies.h"
#include "stokesrods/sim/integrator.h"

namespace stokesrods {
namespace {

using testing::ModelFromToml;

// Small enough to take about a second: 17 nodes per helix, 80 + 40 surface points, 4 steps of
// 20 ms (the near blocks still matter: without the rods' near blocks at the body points the
// difference is 1.6e-2 R, checked).
constexpr testing::CellCase kCell{.nodes = 17, .cell_points = 80, .fixed_points = 40};
constexpr int kSteps = 4;

struct Series {
  std::vector<VecX> q;         // rods' DOFs after each step
  std::vector<VecX> body;      // the cell's centre, (U, Ω) and the fluid's force on it
  double products_per_newton = 0.0;
};

Series RunCell(const std::string& fluid, int steps, double h = 0.02) {
  const Model model = ModelFromToml(testing::SwimmingCellToml(kCell, fluid));
  State state = MakeRestState(model);
  Workspace ws(model);
  Series s;
  long products = 0, newton = 0;
  for (int k = 0; k < steps; ++k) {
    const StepReport r = Step(model, h, &state, &ws);
    EXPECT_TRUE(r.ok) << r.message;
    if (!r.ok) break;
    // Every GMRES solve of the step reached its tolerance (within 200 products).
    EXPECT_TRUE(ws.hydro.worst_solve().ok) << fluid << ": step " << k;
    products += r.krylov_iterations;
    newton += r.newton_iterations;
    s.q.push_back(state.q);
    VecX b(12);
    b << state.bodies[0].center, BodyVelocity(model, 0, ws.hydro_force),
        BodyHydroLoad(model, 0, state.bodies[0], ws.hydro_force).head<3>();
    s.body.push_back(b);
  }
  s.products_per_newton = newton ? static_cast<double>(products) / static_cast<double>(newton) : 0.0;
  return s;
}

void Compare(const Series& ref, const Series& fast, const char* name, double tolerance) {
  ASSERT_EQ(ref.q.size(), fast.q.size());
  constexpr double kHelixRadius = 0.008;
  double dq = 0, du = 0, domega = 0, dforce = 0, u_scale = 0, omega_scale = 0, force_scale = 0;
  auto largest = [](const auto& v) { return v.cwiseAbs().maxCoeff(); };
  for (std::size_t i = 0; i < ref.q.size(); ++i) {
    const VecX& a = ref.body[i];
    const VecX& b = fast.body[i];
    dq = std::max({dq, largest(ref.q[i] - fast.q[i]), largest(a.head<3>() - b.head<3>())});
    du = std::max(du, largest(a.segment<3>(3) - b.segment<3>(3)));
    domega = std::max(domega, largest(a.segment<3>(6) - b.segment<3>(6)));
    dforce = std::max(dforce, largest(a.tail<3>() - b.tail<3>()));
    u_scale = std::max(u_scale, largest(a.segment<3>(3)));
    omega_scale = std::max(omega_scale, largest(a.segment<3>(6)));
    force_scale = std::max(force_scale, largest(a.tail<3>()));
  }
  std::printf("%s: max |Δq| = %.2e R, max |ΔU| = %.2e of max |U|, max |ΔΩ| = %.2e of max |Ω|, "
              "max |ΔF_body| = %.2e of max |F_body|; GMRES products per Newton iteration %.1f\n",
              name, dq / kHelixRadius, du / u_scale, domega / omega_scale, dforce / force_scale,
              fast.products_per_newton);
  EXPECT_LT(dq, tolerance * kHelixRadius);
  EXPECT_LT(du, tolerance * u_scale);
  EXPECT_LT(domega, tolerance * omega_scale);
  EXPECT_LT(dforce, tolerance * force_scale);
}

TEST(MatrixFreeBodies, SwimmingCellAsTheDenseReference) {
  const Series ref = RunCell("mobility = \"dense\"\nsolver = \"direct\"", kSteps);
  ASSERT_EQ(ref.q.size(), static_cast<std::size_t>(kSteps));
  std::printf("reference: U_z = %.4e m/s, Omega_z = %.4e rad/s after %d steps\n",
              ref.body.back()(5), ref.body.back()(8), kSteps);
  Compare(ref, RunCell("mobility = \"dense\"\nsolver = \"krylov\"", kSteps),
          "dense + GMRES (LU of C)", 1e-6);
  Compare(ref,
          RunCell("mobility = \"matrix_free\"\nfar_field_tolerance = 1e-8\nfast_sum_tolerance = 1e-8",
                  kSteps),
          "matrix-free (far field 1e-8) + GMRES (bordered blocks, coarse level)", 1e-6);
  // With bodies the far-field sum runs in double, at most 1e-5 (io/build_model.cc).
  Compare(ref, RunCell("mobility = \"matrix_free\"", kSteps),
          "matrix-free (defaults with bodies: far field 1e-5) + GMRES", 1e-5);
}

}  // namespace
}  // namespace stokesrods
