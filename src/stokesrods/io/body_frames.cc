// The bodies' ParaView frames (writers.h): surface points as vertices.
#include <fmt/format.h>

#include "stokesrods/io/vtk_arrays.h"
#include "stokesrods/io/writers.h"
#include "stokesrods/sim/bodies.h"

namespace stokesrods {

std::string BodyFrameXml(const Model& model, const State& state, const VecX* body_forces,
                         VtkFormat format) {
  const std::vector<BodySurface> surfaces = BodySurfaces(model, state.bodies);
  const VecX velocity = BodyPointVelocities(model, state.bodies);  // free bodies: 0
  const std::size_t p = static_cast<std::size_t>(model.num_body_points);
  std::vector<double> points, velocities(velocity.data(), velocity.data() + 3 * p);
  std::vector<std::int32_t> connectivity, offsets, body_id;
  for (std::size_t k = 0; k < surfaces.size(); ++k)
    for (Eigen::Index j = 0; j < surfaces[k].points.cols(); ++j) {
      const Vec3 x = surfaces[k].points.col(j);
      points.insert(points.end(), {x.x(), x.y(), x.z()});
      connectivity.push_back(static_cast<std::int32_t>(body_id.size()));
      offsets.push_back(static_cast<std::int32_t>(body_id.size() + 1));
      body_id.push_back(static_cast<std::int32_t>(k + 1));
    }
  VtkArrays arrays(format);
  std::string xml = PolyDataStart(&arrays, points, "Verts", connectivity, offsets);
  xml += arrays.Add("body", body_id, 1);
  xml += arrays.Add("velocity", velocities, 3, 8);
  if (body_forces != nullptr && static_cast<std::size_t>(body_forces->size()) == 3 * p)
    xml += arrays.Add("hydrodynamic_force",
                      std::vector<double>(body_forces->data(), body_forces->data() + 3 * p), 3, 8);
  return xml + PolyDataEnd(arrays);
}

}  // namespace stokesrods
