#include "stokesrods/sim/obstacle_contact.h"

#include <algorithm>

namespace stokesrods {

std::vector<ObstaclePair> DetectObstacleContacts(const Model& model, const VecX& q,
                                                 const std::vector<BodyPose>& poses) {
  std::vector<ObstaclePair> pairs;
  for (int r = 0; r < static_cast<int>(model.rods.size()); ++r) {
    const RodModel& rod = model.rods[static_cast<std::size_t>(r)];
    for (int i = 0; i < rod.num_nodes(); ++i) {
      if (std::binary_search(rod.fixed_dofs.begin(), rod.fixed_dofs.end(), NodeDof(i))) continue;
      const Vec3 x = q.segment<3>(rod.dof_offset + NodeDof(i));
      auto consider = [&](int body, const Vec3& normal, const Vec3& point, double distance) {
        if (distance < rod.radius) pairs.push_back({r, i, body, normal, point, rod.radius - distance});
      };
      if (model.fluid.wall) {
        const Wall& wall = *model.fluid.wall;
        const double d = wall.normal.dot(x - wall.point);
        consider(-1, wall.normal, x - d * wall.normal, d);
      }
      for (int k = 0; k < static_cast<int>(model.bodies.size()); ++k) {
        const Vec3 c = poses[static_cast<std::size_t>(k)].center;
        const double a = model.bodies[static_cast<std::size_t>(k)].radius;
        const Vec3 n = (x - c).normalized();
        consider(k, n, c + a * n, (x - c).norm() - a);
      }
    }
  }
  return pairs;
}

void AddObstacleReaction(const Model& model, const ObstaclePair& pair, const Vec3& force,
                         const std::vector<BodyPose>& poses, VecX* loads) {
  if (pair.body < 0) return;
  const BodyModel& body = model.bodies[static_cast<std::size_t>(pair.body)];
  if (body.free_index < 0) return;
  const Vec3 arm = pair.point - poses[static_cast<std::size_t>(pair.body)].center;
  loads->segment<3>(6 * body.free_index) -= force;
  loads->segment<3>(6 * body.free_index + 3) -= arm.cross(force);
}

}  // namespace stokesrods
