#include "stokesrods/sim/observables.h"

#include <cmath>

#include <fmt/format.h>

#include "stokesrods/sim/bodies.h"
#include "stokesrods/sim/contact_forces.h"

namespace stokesrods {

Scales CalcScales(const Model& model) {
  if (model.rods.empty()) return {1.0, 1.0};  // bodies only: SI units
  const RodModel& rod = model.rods.front();
  const double l0 = rod.axis_length;
  return {model.fluid.viscosity * std::pow(l0, 4) / rod.bending_stiffness,
          rod.bending_stiffness / (l0 * l0)};
}

std::vector<std::string> TimeseriesColumns(const Model& model) {
  std::vector<std::string> names = {"time", "t_bar"};
  const int rods = static_cast<int>(model.rods.size());
  for (int k = 1; k <= rods; ++k)
    for (const char* c : {"end_x", "end_y", "end_z", "length", "length_bar", "force_x", "force_y",
                          "force_z", "torque_z"})
      names.push_back(fmt::format("rod{}_{}", k, c));
  names.insert(names.end(), {"propulsive_force", "propulsive_force_bar"});
  if (rods >= 2) names.insert(names.end(), {"delta_b", "delta_b_over_R", "min_distance", "contacts"});
  for (int k = 1; k <= rods; ++k) names.push_back(fmt::format("rod{}_tip_axis_distance", k));
  names.insert(names.end(), {"max_penetration", "newton_iterations"});
  for (int k = 1; k <= static_cast<int>(model.bodies.size()); ++k)  // SPEC "Additions"
    for (const char* c : {"x", "y", "z", "force_x", "force_y", "force_z", "omega_x", "omega_y",
                          "omega_z"})
      names.push_back(fmt::format("body{}_{}", k, c));
  return names;
}

std::vector<double> CalcTimeseriesRow(const Model& model, const State& state, const Workspace& ws,
                                      const StepReport& report) {
  const Scales scales = CalcScales(model);
  std::vector<double> row = {state.time, state.time / scales.time};
  double propulsive = 0.0;
  std::vector<Vec3> ends;
  for (int r = 0; r < static_cast<int>(model.rods.size()); ++r) {
    const RodModel& rod = model.rods[r];
    const Vec3 first = state.q.segment<3>(rod.dof_offset);
    const Vec3 last = state.q.segment<3>(rod.dof_offset + NodeDof(rod.num_nodes() - 1));
    ends.push_back(last);
    const double length = (last - first).norm();
    const ClampLoad clamp = CalcClampLoad(model, state, ws, r);
    propulsive += clamp.force.z();
    row.insert(row.end(), {last.x(), last.y(), last.z(), length, length / rod.axis_length,
                           clamp.force.x(), clamp.force.y(), clamp.force.z(), clamp.torque_z});
  }
  row.insert(row.end(), {propulsive, propulsive / scales.force});
  if (model.rods.size() >= 2) {
    const double delta_b = ends[1].x() - ends[0].x();
    const double R = model.rods[0].helix_radius;
    row.insert(row.end(), {delta_b, R > 0.0 ? delta_b / R : std::nan(""),
                           MinDistanceBetweenRods(model, state.q),
                           static_cast<double>(report.contact_pairs)});
  }
  for (int r = 0; r < static_cast<int>(model.rods.size()); ++r) {
    const RodModel& rod = model.rods[r];
    const Vec3 d = ends[r] - state.q.segment<3>(rod.dof_offset);
    row.push_back(d.head<2>().norm());
  }
  row.insert(row.end(), {report.contact.max_penetration,
                         static_cast<double>(report.newton_iterations)});
  for (int k = 0; k < static_cast<int>(model.bodies.size()); ++k) {
    const BodyPose& pose = state.bodies[static_cast<size_t>(k)];
    const Vec3 c = pose.center;
    // The fluid's force and the body's angular velocity of the last step (sim/bodies.h).
    const bool solved = ws.hydro_force.size() == model.hydro_size();
    const Vec3 f = solved ? Vec3(BodyHydroLoad(model, k, pose, ws.hydro_force).head<3>()) : Vec3::Zero();
    const Vec3 w = solved ? Vec3(BodyVelocity(model, k, ws.hydro_force).tail<3>())
                          : Vec3(model.bodies[static_cast<size_t>(k)].angular_velocity);
    row.insert(row.end(), {c.x(), c.y(), c.z(), f.x(), f.y(), f.z(), w.x(), w.y(), w.z()});
  }
  return row;
}

}  // namespace stokesrods
