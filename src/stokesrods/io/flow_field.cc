#include "stokesrods/io/flow_field.h"

#include <filesystem>

#include <Eigen/LU>
#include <fmt/format.h>

#include "stokesrods/io/writers.h"
#include "stokesrods/fluid/mobility_operator.h"
#include "stokesrods/sim/bodies.h"
#include "stokesrods/sim/capacitance_preconditioner.h"
#include "stokesrods/sim/hydro_coupling.h"
#include "stokesrods/solver/gmres.h"

namespace stokesrods {

namespace fs = std::filesystem;

std::string WriteFlowField(const Model& model, const State& state, const FlowFieldConfig& plane,
                           const std::string& output_dir, int index) {
  std::vector<Matrix3X> positions;
  for (int r = 0; r < static_cast<int>(model.rods.size()); ++r)
    positions.push_back(RodPositions(model, r, state.q));
  const std::vector<HydroRod> rods = MakeHydroRods(model, positions);
  VecX u;
  GatherNodeVelocities(model, state.velocity, VecX::Zero(state.velocity.size()), 1.0, &u);
  // The bodies' points follow the rods' nodes, with their rigid velocities.
  // Free bodies' (U, Ω) are solved with their balance (the bordered mobility's last rows, 0 here).
  const std::vector<BodySurface> bodies = BodySurfaces(model, state.bodies);
  u.conservativeResize(model.hydro_size());
  u.tail(model.hydro_size() - 3 * model.num_nodes).setZero();
  u.segment(3 * model.num_nodes, 3 * model.num_body_points) = BodyPointVelocities(model, state.bodies);
  // The nodal forces on the fluid at the current positions and velocities, 𝕄 F = U: a dense LU
  // while 𝕄 is dense; with the matrix-free operator GMRES, preconditioned by the rods' own
  // self-mobilities and the bodies' bordered blocks (a dense 𝕄 of a hundred flagella would take
  // 3 GB).
  VecX forces;
  const std::unique_ptr<MobilityOperator> mobility = MakeModelMobility(model);
  mobility->UpdateWithBodies(rods, bodies);
  if (const MatX* m = mobility->matrix()) {
    forces = m->partialPivLu().solve(u);
  } else {
    // The blocks of 𝕄 itself (h = 1, no elastic part): each rod's, each body's bordered by its V.
    std::vector<MatX> self(model.rods.size());
    for (int r = 0; r < static_cast<int>(self.size()); ++r) self[static_cast<size_t>(r)] = mobility->SelfBlock(r);
    CapacitancePreconditioner blocks;
    if (!blocks.Build(model, 1.0, self, rods, bodies, nullptr, false))
      throw IoError(fmt::format("{}: flow field not written: a block of the mobility is singular",
                                output_dir));
    const LinearOperator apply = [&](const VecX& x, VecX* y) { mobility->Apply(x, y); };
    const LinearOperator precondition = [&](const VecX& x, VecX* y) { blocks.Apply(x, y); };
    const GmresReport g = SolveGmres(apply, precondition, u, {.tolerance = 1e-10}, &forces);
    if (!g.converged)
      throw IoError(fmt::format("{}: flow field not written: the mobility solve reached only {:.1e} "
                                "after {} iterations", output_dir, g.relative_residual,
                                g.iterations));
  }

  const int nu = plane.resolution[0], nv = plane.resolution[1];
  std::string vts = fmt::format(
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"StructuredGrid\" version=\"0.1\">\n"
      "<StructuredGrid WholeExtent=\"0 {0} 0 {1} 0 0\">\n<Piece Extent=\"0 {0} 0 {1} 0 0\">\n",
      nu - 1, nv - 1);
  std::string points, velocity, csv = "x,y,z,ux,uy,uz\n";
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const Vec3 x = plane.origin + plane.u * i / (nu - 1.0) + plane.v * j / (nv - 1.0);
      // Below a wall there is no fluid.
      const bool below = model.fluid.wall &&
                         (x - model.fluid.wall->point).dot(model.fluid.wall->normal) < 0.0;
      const Vec3 w = below ? Vec3(Vec3::Zero())
                           : Vec3(FluidVelocityAt(model.fluid, rods, forces.head(3 * model.num_nodes), x) +
                                  BodyBlobVelocityAt(model.fluid, bodies,
                                                     forces.segment(3 * model.num_nodes, 3 * model.num_body_points), x));
      points += fmt::format("{:.8g} {:.8g} {:.8g}\n", x.x(), x.y(), x.z());
      velocity += fmt::format("{:.8g} {:.8g} {:.8g}\n", w.x(), w.y(), w.z());
      csv += fmt::format("{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g}\n", x.x(), x.y(), x.z(), w.x(),
                         w.y(), w.z());
    }
  vts += "<PointData Vectors=\"velocity\">\n<DataArray type=\"Float64\" Name=\"velocity\" "
         "NumberOfComponents=\"3\" format=\"ascii\">\n" + velocity + "</DataArray>\n</PointData>\n";
  vts += "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n" +
         points + "</DataArray>\n</Points>\n</Piece>\n</StructuredGrid>\n</VTKFile>\n";
  std::error_code ec;
  fs::create_directories(fs::path(output_dir) / "flow", ec);
  if (ec) throw IoError(fmt::format("{}/flow: cannot create: {}", output_dir, ec.message()));
  const std::string name = fmt::format("flow/flow_{:05d}", index);
  WriteFileAtomically((fs::path(output_dir) / (name + ".vts")).string(), vts);
  WriteFileAtomically((fs::path(output_dir) / (name + ".csv")).string(), csv);
  return name + ".vts";
}

}  // namespace stokesrods
