// stokesrods._core.Simulation: step-by-step control of one case (controllers, soft robots).
// Rods count from 1 as in the output columns; nodes from 0 as in the paper.
#include <memory>

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings/convert.h"
#include "stokesrods/io/simulation.h"
#include "stokesrods/sim/observables.h"

namespace py = pybind11;

namespace stokesrods::python {
namespace {

using NodeArray = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

int RodIndex(const Simulation& sim, int rod) {
  const int count = static_cast<int>(sim.model().rods.size());
  if (rod < 1 || rod > count)
    throw py::index_error(fmt::format("rod {} does not exist (rods count from 1; there are {})", rod, count));
  return rod - 1;
}

// Nodes of rod r from a global DOF vector (q, velocity, ...) as an N × 3 array.
NodeArray RodNodes(const Simulation& sim, int rod, const VecX& dofs) {
  return RodPositions(sim.model(), RodIndex(sim, rod), dofs).transpose();
}

void StepMany(Simulation& sim, long n) {
  if (sim.plan().static_mode)
    throw py::value_error("run.mode = \"static\": use solve_static(), not step()");
  for (long k = 0; k < n; ++k) {
    StepReport report;
    {
      py::gil_scoped_release release;
      report = sim.Step();
    }
    if (!report.ok)
      throw std::runtime_error(fmt::format("numerical failure at t = {:.6g} s: {}; the state is "
                                           "the last good one",
                                           sim.state().time, report.message));
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
}

py::dict Observables(const Simulation& sim) {
  const std::vector<std::string> columns = TimeseriesColumns(sim.model());
  const std::vector<double> row =
      CalcTimeseriesRow(sim.model(), sim.state(), sim.workspace(), sim.last_report());
  py::dict d;
  for (std::size_t i = 0; i < columns.size(); ++i) d[py::str(columns[i])] = row[i];
  return d;
}

py::dict ClampLoadDict(const Simulation& sim, int rod) {
  const ClampLoad load = CalcClampLoad(sim.model(), sim.state(), sim.workspace(), RodIndex(sim, rod));
  py::dict d;
  d["force"] = Vec3(load.force);
  d["torque_z"] = load.torque_z;
  return d;
}

// Per-node forces of the last step on rod r [N]: the drag of a nonlocal fluid and contact.
py::dict NodeForces(const Simulation& sim, int rod) {
  const int r = RodIndex(sim, rod);
  const RodModel& m = sim.model().rods[r];
  const Workspace& ws = sim.workspace();
  NodeArray hydro = NodeArray::Zero(m.num_nodes(), 3), contact = NodeArray::Zero(m.num_nodes(), 3);
  for (int i = 0; i < m.num_nodes(); ++i) {
    if (ws.nonlocal_fluid) hydro.row(i) = ws.hydro_force.segment<3>(3 * (m.node_offset + i));
    contact.row(i) = ws.contact_force.segment<3>(m.dof_offset + NodeDof(i));
  }
  py::dict d;
  d["hydrodynamic"] = hydro;
  d["contact"] = contact;
  return d;
}

void SetLoads(Simulation& sim, int rod, const py::dict& loads) {
  std::vector<PointLoad> list;
  for (auto [node, force] : loads) list.push_back({node.cast<int>(), force.cast<Vec3>()});
  try {
    sim.SetLoads(RodIndex(sim, rod), std::move(list));
  } catch (const std::out_of_range& e) {
    throw py::index_error(e.what());
  }
}

py::dict Loads(const Simulation& sim, int rod) {
  py::dict d;
  for (const PointLoad& l : sim.model().rods[RodIndex(sim, rod)].loads) d[py::int_(l.node)] = l.force;
  return d;
}

}  // namespace

void BindSimulation(py::module_& m) {
  py::class_<Simulation, std::unique_ptr<Simulation>>(m, "Simulation", R"doc(
One case stepped by the caller: Simulation(config, overrides=None) with config a TOML path or a
dict of the same schema. Rods count from 1 (as in the output columns), nodes from 0.)doc")
      .def(py::init([](const py::object& config, const py::object& overrides) {
             return std::make_unique<Simulation>(ConfigFromPython(config, overrides));
           }),
           py::arg("config"), py::arg("overrides") = py::none())
      .def("step", &StepMany, py::arg("n") = 1,
           "Advances n steps of run.time_step; raises RuntimeError on a numerical failure.")
      .def("solve_static", [](Simulation& sim) {
             StepReport report = sim.SolveStatic();
             if (!report.ok) throw std::runtime_error("static solve failed: " + report.message);
           })
      .def_property_readonly("time", [](const Simulation& s) { return s.state().time; })
      .def_property_readonly("steps", [](const Simulation& s) { return s.state().step; })
      .def_property_readonly("time_step", [](const Simulation& s) { return s.plan().time_step; })
      .def_property_readonly("duration", [](const Simulation& s) { return s.plan().duration; })
      .def_property_readonly("num_rods", [](const Simulation& s) { return s.model().rods.size(); })
      .def_property_readonly("config_toml", [](const Simulation& s) { return ConfigToToml(s.config()); })
      .def("positions", [](const Simulation& s, int rod) { return RodNodes(s, rod, s.state().q); },
           py::arg("rod"), "Node positions of a rod, N × 3 [m].")
      .def("velocities",
           [](const Simulation& s, int rod) { return RodNodes(s, rod, s.state().velocity); },
           py::arg("rod"), "Node velocities of a rod, N × 3 [m/s].")
      .def("twist_angles",
           [](const Simulation& s, int rod) {
             const RodModel& rm = s.model().rods[RodIndex(s, rod)];
             VecX theta(rm.num_nodes() - 1);
             for (int j = 0; j + 1 < rm.num_nodes(); ++j) theta(j) = s.state().q(rm.dof_offset + TwistDof(j));
             return theta;
           },
           py::arg("rod"), "The twist angles θ of the rod's edges [rad] (N − 1).")
      .def("clamp_load", &ClampLoadDict, py::arg("rod"),
           "Reaction on the clamped nodes (paper eq. 25): {'force': [N], 'torque_z': [N·m]}.")
      .def("node_forces", &NodeForces, py::arg("rod"),
           "Per-node forces of the last step: {'hydrodynamic': N × 3, 'contact': N × 3} [N].")
      .def("observables", &Observables, "The timeseries.csv columns at the current state, as a dict.")
      .def("omega", [](const Simulation& s, int rod) { return s.model().rods[RodIndex(s, rod)].omega; },
           py::arg("rod"), "The imposed rotation rate of a rod about +z [rad/s].")
      .def("set_omega", [](Simulation& s, int rod, double omega) { s.SetOmega(RodIndex(s, rod), omega); },
           py::arg("rod"), py::arg("omega"),
           "Sets a rod's imposed rotation rate about +z [rad/s] from the next step on.")
      .def("loads", &Loads, py::arg("rod"), "The rod's point loads {node: force [N]}.")
      .def("set_loads", &SetLoads, py::arg("rod"), py::arg("loads"),
           "Replaces the rod's point loads by {node: [fx, fy, fz]} [N] from the next step on.")
      .def("save_checkpoint", &Simulation::SaveCheckpoint, py::arg("path"),
           "Writes the state and the controls (omega, point loads) to a checkpoint file.")
      .def("load_checkpoint", &Simulation::LoadCheckpoint, py::arg("path"),
           "Replaces the state and the controls (omega, point loads) by a checkpoint's (written by\n"
           "save_checkpoint or a run).");
}

}  // namespace stokesrods::python
