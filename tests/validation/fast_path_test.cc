// The fast hydrodynamic paths against the reference they replace, on whole time series:
//   reference : dense 𝕄 assembled at every step, the capacitance C = h𝕄 + S X by a fresh dense
//               LU at every step;
//   krylov    : dense 𝕄, C by GMRES preconditioned with a kept LU (the default up to 500 nodes),
//               applied in the rods' turned frames (the default) or as built;
//   reuse     : dense 𝕄 extrapolated between assemblies (fluid/mobility_reuse.h; on by default),
//               compared with 𝕄 assembled at every step on its own (it is left off where the
//               solvers are compared: it makes 𝕄 depend on where the assemblies fall, which a
//               solver's own differences can move);
//   matrix_free: 𝕄 never formed (exact near pairs, Gauss far field, Stokeslet sum), GMRES with
//               per-rod block preconditioning (the default above 500 nodes).
// All solve the same discrete equations; the fast ones stop GMRES at the Newton tolerance, and
// matrix-free also carries the far-field tolerance (1e-8). Expected difference: the Newton
// tolerance (1e-8 of the force scale) times the system's compliance, ~1e-9 of the rod length over
// these runs; we allow 1e-6 of the helix radius on positions and 1e-6 of the largest clamp force
// on forces, which is far below what any physical change makes (the regression test's changes)
// and far above round-off.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

#include <omp.h>

#include "common/model_from_toml.h"
#include "stokesrods/sim/integrator.h"
#include "stokesrods/sim/observables.h"

namespace stokesrods {
namespace {

using testing::ModelFromToml;

struct Series {
  std::vector<VecX> q;           // positions every `every` steps
  std::vector<VecX> clamp_force; // per rod z force and torque, same times
  double krylov_per_step = 0.0;
  double newton_per_step = 0.0;
};

Series RunSeries(const Model& model, int steps, int every, double h = 0.01) {
  State state = MakeRestState(model);
  Workspace ws(model);
  Series s;
  long krylov = 0, newton = 0;
  for (int k = 1; k <= steps; ++k) {
    const StepReport r = Step(model, h, &state, &ws);
    EXPECT_TRUE(r.ok) << r.message;
    if (!r.ok) break;
    krylov += r.krylov_iterations;
    newton += r.newton_iterations;
    if (k % every) continue;
    s.q.push_back(state.q);
    VecX loads(2 * model.rods.size());
    for (int rod = 0; rod < static_cast<int>(model.rods.size()); ++rod) {
      const ClampLoad load = CalcClampLoad(model, state, ws, rod);
      loads(2 * rod) = load.force.z();
      loads(2 * rod + 1) = load.torque_z;
    }
    s.clamp_force.push_back(loads);
  }
  s.krylov_per_step = static_cast<double>(krylov) / steps;
  s.newton_per_step = static_cast<double>(newton) / steps;
  return s;
}

Series RunSeries(const std::string& toml, int steps, int every, double h = 0.01) {
  return RunSeries(ModelFromToml(toml), steps, every, h);
}

// Largest difference over the series: positions [m], clamp loads relative to the largest; both
// within `tolerance` (of R and of the largest load).
void Compare(const Series& ref, const Series& fast, double radius, const char* name,
             double tolerance = 1e-6) {
  ASSERT_EQ(ref.q.size(), fast.q.size());
  double dq = 0.0, df = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < ref.q.size(); ++i) {
    dq = std::max(dq, (ref.q[i] - fast.q[i]).cwiseAbs().maxCoeff());
    df = std::max(df, (ref.clamp_force[i] - fast.clamp_force[i]).cwiseAbs().maxCoeff());
    scale = std::max(scale, ref.clamp_force[i].cwiseAbs().maxCoeff());
  }
  std::printf("%s: max |Δq| = %.3e m (%.3e R), max |Δ clamp load| = %.3e of the largest; "
              "GMRES products per step %.1f\n", name, dq, dq / radius, df / scale,
              fast.krylov_per_step);
  EXPECT_LT(dq, tolerance * radius);
  EXPECT_LT(df, tolerance * scale);
}

// The matrix-free far field at 1e-8 (quadrature and sum), compared at the default 1e-6; and at
// its defaults (far field accurate to fast_sum_tolerance = 1e-4: two Gauss points, the sum in
// single precision), compared at that accuracy.
const char* const kStrictMatrixFree =
    "mobility = \"matrix_free\"\nfar_field_tolerance = 1e-8\nfast_sum_tolerance = 1e-8";
constexpr double kDefaultFarField = 1e-4;

std::string Fig1(const std::string& fluid, int nodes) {
  // Paper Fig. 1 (two helices 3R apart, ω̄ = 320, contact on), 100 steps of 10 ms.
  return R"(
[run]
duration = 1.0
[fluid]
model = "rss"
)" + fluid + R"(
[contact]
enabled = true
[[rods]]
nodes = )" + std::to_string(nodes) + R"(
omega_bar = 320
[[rods]]
nodes = )" + std::to_string(nodes) + R"(
omega_bar = 320
base = [0.03, 0.0, 0.0]
)";
}

TEST(FastPath, Fig1TwoFlagella) {
  const std::string dense = "mobility = \"dense\"\nmobility_reuse_tolerance = 0\n";
  const Series ref = RunSeries(Fig1(dense + "solver = \"direct\"", 65), 60, 10);
  Compare(ref, RunSeries(Fig1(dense + "solver = \"krylov\"", 65), 60, 10), 0.01,
          "Fig. 1, dense + GMRES");
  Compare(ref,
          RunSeries(Fig1(dense + "solver = \"krylov\"\nkrylov_rotate_preconditioner = false", 65),
                    60, 10),
          0.01, "Fig. 1, dense + GMRES, the kept preconditioner as built");
  Compare(ref, RunSeries(Fig1(kStrictMatrixFree, 65), 60, 10), 0.01,
          "Fig. 1, matrix-free (far field 1e-8) + GMRES");
  Compare(ref, RunSeries(Fig1("mobility = \"matrix_free\"", 65), 60, 10), 0.01,
          "Fig. 1, matrix-free (defaults: far field 1e-4) + GMRES", kDefaultFarField);
}

// Fig. 1 at the paper's h = 1 ms, where the dense 𝕄 is reused across steps (extrapolated in single
// precision between assemblies, fluid/mobility_reuse.h), against 𝕄 assembled at every step (both
// by GMRES: Fig1TwoFlagella checks that against the direct LU). The reuse's tolerance bounds the
// relative error of 𝕄; the time series then differ in proportion to it (measured over these 100
// steps: 2.8e-5 R at 1e-4, 3.0e-6 R at 1e-5; with the linear extrapolation before 2026-11-25,
// 4.8e-5 and 3.3e-6). Allowed: 2 × tolerance × R and of the largest
// clamp load, and ten times the tolerance at least five times the difference (a reuse that
// ignored its tolerance would not scale).
TEST(FastPath, Fig1AtOneMillisecondWithTheReusedMobility) {
  std::string fig1 = Fig1("mobility = \"dense\"\nmobility_reuse_tolerance = TOL", 65);
  fig1.replace(fig1.find("[run]\n"), 6, "[run]\ntime_step = 1e-3\n");
  auto with = [&](const std::string& tolerance) {
    std::string t = fig1;
    t.replace(t.find("TOL"), 3, tolerance);
    return RunSeries(t, 100, 10, 1e-3);
  };
  const Series reference = with("0");
  auto largest = [&](const Series& s) {
    double d = 0.0;
    for (std::size_t i = 0; i < s.q.size(); ++i)
      d = std::max(d, (s.q[i] - reference.q[i]).cwiseAbs().maxCoeff());
    return d;
  };
  const Series coarse = with("1e-4"), fine = with("1e-5");
  Compare(reference, coarse, 0.01, "Fig. 1 at 1 ms, dense 𝕄 reused at 1e-4", 2e-4);
  Compare(reference, fine, 0.01, "Fig. 1 at 1 ms, dense 𝕄 reused at 1e-5", 2e-5);
  EXPECT_GT(largest(coarse), 5.0 * largest(fine));
}

// The same at h = 10 ms (60 steps), where the quadratic extrapolation reuses 𝕄 too (the linear
// one assembled at every step there: tests/fluid/mobility_reuse_test.cc): within 2 × tolerance.
TEST(FastPath, Fig1AtTenMillisecondsWithTheReusedMobility) {
  auto with = [](const std::string& tolerance) {
    return RunSeries(Fig1("mobility = \"dense\"\nmobility_reuse_tolerance = " + tolerance, 65),
                     60, 10);
  };
  Compare(with("0"), with("1e-4"), 0.01, "Fig. 1 at 10 ms, dense 𝕄 reused at 1e-4", 2e-4);
}

// Newton's factors kept across steps (modified Newton: solver.jacobian_max_age = 5) against
// fresh ones at every step (the default), on Fig. 1 at h = 1 ms (200 steps,
// 𝕄 assembled at every step so that only the factors differ). Both meet the same residual
// tolerance, but a fresh factorization's one iteration lands far inside it and a kept one's
// nearer its edge (here the round-off floor of the stretching forces, above 1e-8 of the force
// scale). Measured: 4.9e-8 R and 2.9e-8 of the largest clamp load; allowed, as every fast path
// here: 1e-6 of both.
TEST(FastPath, KeptNewtonFactorsAgainstFreshOnes) {
  std::string fig1 = Fig1("mobility = \"dense\"\nmobility_reuse_tolerance = 0", 65);
  fig1.replace(fig1.find("[run]\n"), 6, "[run]\ntime_step = 1e-3\n");
  auto with = [&](int age) {
    return RunSeries(fig1 + "[solver]\njacobian_max_age = " + std::to_string(age) + "\n", 200,
                     20, 1e-3);
  };
  Compare(with(1), with(5), 0.01, "Fig. 1 at 1 ms, Newton factors kept 5 steps");
}

// At h = 10 ms kept factors leave most steps needing a second Newton iteration; after each such
// step they are set aside for 1, 2, 4 … 64 steps (sim/newton.cc). Measured on Fig. 1 over these
// 100 steps from rest: with jacobian_max_age = 5, 1.40 Newton iterations per step against 1.26
// with fresh factors (ratio 1.11), 1.58 without the back-off (1.25). Allowed: a ratio of 1.18,
// between the two; and the series within 1e-6, as every fast path.
TEST(FastPath, KeptNewtonFactorsAreSetAsideWhereTheyDoNotConverge) {
  auto with = [](int age) {
    return RunSeries(Fig1("", 65) + "[solver]\njacobian_max_age = " + std::to_string(age) + "\n",
                     100, 10);
  };
  const Series fresh = with(1), kept = with(5);
  std::printf("Fig. 1 at 10 ms: Newton iterations per step %.3f fresh, %.3f kept\n",
              fresh.newton_per_step, kept.newton_per_step);
  EXPECT_LT(kept.newton_per_step, 1.18 * fresh.newton_per_step);
  Compare(fresh, kept, 0.01, "Fig. 1 at 10 ms, Newton factors kept 5 steps");
}

// The explicit coupling (paper Algorithm 1) solves 𝕄 f = −U once per step: dense LU against
// GMRES with the matrix-free operator, at its stable step. And LSBT (dense only) through GMRES
// against its direct solve.
TEST(FastPath, ExplicitCouplingAndLsbt) {
  auto two_helices = [](const std::string& fluid, int nodes) {
    return R"(
[run]
duration = 1.0
time_step = 2e-4
[fluid]
)" + fluid + R"(
[contact]
enabled = true
[[rods]]
nodes = )" + std::to_string(nodes) + R"(
axis_length = 0.1
helix_radius = 0.008
omega_bar = 300
[[rods]]
nodes = )" + std::to_string(nodes) + R"(
axis_length = 0.1
helix_radius = 0.008
base = [0.0175, 0.0, 0.0]
omega_bar = 300
)";
  };
  const std::string explicit_rss = "model = \"rss\"\ncoupling = \"explicit\"\n";
  // The reference assembles 𝕄 at every step (its reuse, on by default at such small steps, is
  // tested in tests/fluid/mobility_reuse_test.cc).
  const Series ref = RunSeries(
      two_helices(explicit_rss + "mobility = \"dense\"\nmobility_reuse_tolerance = 0", 15), 40, 10,
      2e-4);
  Compare(ref, RunSeries(two_helices(explicit_rss + kStrictMatrixFree, 15), 40, 10, 2e-4),
          0.008, "explicit coupling, matrix-free + GMRES");
  // LSBT needs edges of length r0√e: the paper's helix with N = 195 (appendix C).
  const std::string lsbt = R"(
[run]
duration = 1.0
[fluid]
model = "lsbt"
SOLVER
[contact]
enabled = true
[[rods]]
nodes = 195
omega_bar = 320
[[rods]]
nodes = 195
omega_bar = 320
base = [0.03, 0.0, 0.0]
)";
  auto with = [&](const std::string& solver) {
    std::string t = lsbt;
    t.replace(t.find("SOLVER"), 6, solver);
    return t;
  };
  const Series lsbt_ref = RunSeries(with("solver = \"direct\""), 20, 5, 1e-3);
  Compare(lsbt_ref, RunSeries(with("solver = \"krylov\""), 20, 5, 1e-3), 0.01,
          "LSBT, dense + GMRES");
}

// Ten helices (25 nodes each) on a ring with neighbouring bases 3R apart, with `fluid`'s keys.
std::string TenFlagella(const std::string& fluid) {
  std::string toml = R"(
[run]
duration = 1.0
[fluid]
model = "rss"
)" + fluid + R"(
[contact]
enabled = true
)";
  const double ring = 0.03 / (2.0 * std::sin(kPi / 10.0));
  for (int k = 0; k < 10; ++k)
    toml += "[[rods]]\nnodes = 25\nomega_bar = 320\nbase = [" +
            std::to_string(ring * std::cos(2 * kPi * k / 10)) + ", " +
            std::to_string(ring * std::sin(2 * kPi * k / 10)) + ", 0.0]\n";
  return toml;
}

TEST(FastPath, TenFlagellaOnARing) {
  // 20 steps.
  const auto with = TenFlagella;
  const std::string dense = "mobility = \"dense\"\nmobility_reuse_tolerance = 0\n";
  const Series ref = RunSeries(with(dense + "solver = \"direct\""), 20, 5);
  Compare(ref, RunSeries(with(dense + "solver = \"krylov\""), 20, 5), 0.01,
          "10 flagella, dense + GMRES");
  Compare(ref, RunSeries(with(kStrictMatrixFree), 20, 5), 0.01,
          "10 flagella, matrix-free (far field 1e-8) + GMRES");
  Compare(ref, RunSeries(with("mobility = \"matrix_free\""), 20, 5), 0.01,
          "10 flagella, matrix-free (defaults: far field 1e-4) + GMRES", kDefaultFarField);
  // The far field by the FMM (forced: at 250 nodes the cost model sums directly), p = 6, the
  // first 10 steps. With so few sources per box the FMM's error is that of single interactions,
  // at most 1.8e-4 relative at p = 6 (fluid/fmm_sum.cc); we allow 2e-4 on positions (of R) and
  // loads.
  Model fmm = ModelFromToml(with("mobility = \"matrix_free\"\nfast_sum_tolerance = 1.25e-6"));
  fmm.hydro.mobility.direct_sum_below = 0.0;
  fmm.hydro.mobility.fast_sum_by_cost = false;
  Series first = ref;
  first.q.resize(2);
  first.clamp_force.resize(2);
  Compare(first, RunSeries(fmm, 10, 5), 0.01, "10 flagella, matrix-free + FMM (p = 6) + GMRES", 2e-4);
}

// The test suite runs one thread per test (CMakePresets.json's test presets: two tests at a time
// on two cores; two threads each made the suite 4× slower). The parallel loops (the rods' elastic
// forces, the products by blocks of rows, the near blocks, the Stokeslet sums, the extrapolation,
// the LU solves) are checked here instead: two threads step as one, bit for bit (each loop
// writes its own outputs, and every sum runs in the same order on any number of threads), on
// the dense default (Fig. 1, 𝕄 reused) and on the matrix-free default (ten flagella, the far
// field by the FMM, forced), 60 steps of 1 ms.
TEST(FastPath, TwoThreadsStepAsOne) {
  Model fmm = ModelFromToml(TenFlagella("mobility = \"matrix_free\""));
  fmm.hydro.mobility.direct_sum_below = 0.0;
  fmm.hydro.mobility.fast_sum_by_cost = false;
  const Model fig1 = ModelFromToml(Fig1("", 65));
  const Model* const fmm_model = &fmm;
  const int saved = omp_get_max_threads();
  for (const auto& [model, name] : {std::pair{&fig1, "Fig. 1, dense default"},
                                    std::pair{fmm_model, "10 flagella, matrix-free + FMM"}}) {
    omp_set_num_threads(1);
    const Series one = RunSeries(*model, 60, 10, 1e-3);
    omp_set_num_threads(2);
    const Series two = RunSeries(*model, 60, 10, 1e-3);
    ASSERT_EQ(one.q.size(), two.q.size());
    double dq = 0.0, df = 0.0;
    for (std::size_t i = 0; i < one.q.size(); ++i) {
      dq = std::max(dq, (one.q[i] - two.q[i]).cwiseAbs().maxCoeff());
      df = std::max(df, (one.clamp_force[i] - two.clamp_force[i]).cwiseAbs().maxCoeff());
    }
    std::printf("%s: two threads against one, max |Δq| = %.3e m, max |Δ clamp load| = %.3e N\n",
                name, dq, df);
    EXPECT_EQ(dq, 0.0) << name;
    EXPECT_EQ(df, 0.0) << name;
  }
  omp_set_num_threads(saved);
}

// A wall: the helix of examples/helix_near_wall.toml turned 2 helix radii from the plane
// x = −0.02 m, 30 steps of 10 ms. The matrix-free operator takes the images as sources
// (fluid/wall_sources.h); the dense reference has them in 𝕄. The wall itself moves the nodes by
// 2.0e-4 m (2e-2 R) over these steps (the same run with the wall 10 m away), so a matrix-free
// path without (or with wrong) images fails both comparisons.
TEST(FastPath, HelixNearAWall) {
  auto with = [](const std::string& fluid) {
    return R"(
[run]
duration = 1.0
[fluid]
model = "rss"
)" + fluid + R"(
[[rods]]
nodes = 65
pitch = 0.05
helix_radius = 0.01
clamped_nodes = 2
omega_bar = 533
[wall]
point = [-0.02, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
)";
  };
  const Series ref =
      RunSeries(with("mobility = \"dense\"\nmobility_reuse_tolerance = 0\nsolver = \"direct\""), 30, 10);
  Compare(ref, RunSeries(with(kStrictMatrixFree), 30, 10), 0.01,
          "helix near a wall, matrix-free (far field 1e-8) + GMRES");
  Compare(ref, RunSeries(with("mobility = \"matrix_free\""), 30, 10), 0.01,
          "helix near a wall, matrix-free (defaults: far field 1e-4) + GMRES", kDefaultFarField);
}

}  // namespace
}  // namespace stokesrods
