#include "stokesrods/sim/bodies.h"

#include "stokesrods/common/assert.h"

namespace stokesrods {

Vec3 BodyCenterAt(const BodyModel& body, double time) {
  return body.center + time * body.velocity;
}

Mat3 BodyRotationAt(const BodyModel& body, double time) {
  const double angle = time * body.angular_velocity.norm();
  if (angle == 0.0) return Mat3::Identity();
  return Eigen::AngleAxisd(angle, body.angular_velocity.normalized()).toRotationMatrix();
}

std::vector<BodySurface> BodySurfacesAt(const Model& model, double time) {
  std::vector<BodySurface> surfaces;
  for (const BodyModel& body : model.bodies) {
    BodySurface s;
    s.points = (BodyRotationAt(body, time) * body.surface).colwise() + BodyCenterAt(body, time);
    s.regularization = body.regularization;
    surfaces.push_back(std::move(s));
  }
  return surfaces;
}

VecX BodyPointVelocities(const Model& model, double time) {
  VecX u(3 * model.num_body_points);
  for (const BodyModel& body : model.bodies) {
    const Mat3 rotation = BodyRotationAt(body, time);
    for (int j = 0; j < body.num_points(); ++j)
      u.segment<3>(3 * (body.point_offset + j)) =
          body.velocity + body.angular_velocity.cross(rotation * body.surface.col(j));
  }
  return u;
}

Vec6 BodyHydroLoad(const Model& model, int k, double time, const VecX& f) {
  SR_ASSERT(f.size() == 3 * model.num_hydro_points(), "BodyHydroLoad: drag of the wrong size");
  const BodyModel& body = model.bodies[static_cast<size_t>(k)];
  const Mat3 rotation = BodyRotationAt(body, time);
  Vec6 load = Vec6::Zero();
  for (int j = 0; j < body.num_points(); ++j) {
    const Vec3 fj = f.segment<3>(3 * (model.num_nodes + body.point_offset + j));
    load.head<3>() += fj;
    load.tail<3>() += (rotation * body.surface.col(j)).cross(fj);
  }
  return load;
}

}  // namespace stokesrods
