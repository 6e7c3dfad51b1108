#include "stokesrods/sim/bodies.h"

#include "stokesrods/common/assert.h"

namespace stokesrods {

std::vector<BodySurface> BodySurfaces(const Model& model, const std::vector<BodyPose>& poses) {
  SR_ASSERT(poses.size() == model.bodies.size(), "one pose per body");
  std::vector<BodySurface> surfaces;
  for (std::size_t k = 0; k < model.bodies.size(); ++k) {
    const BodyModel& body = model.bodies[k];
    BodySurface s;
    s.points = (poses[k].rotation * body.surface).colwise() + poses[k].center;
    s.regularization = body.regularization;
    s.free = body.motion == BodyMotion::kFree;
    s.center = poses[k].center;
    surfaces.push_back(std::move(s));
  }
  return surfaces;
}

VecX BodyPointVelocities(const Model& model, const std::vector<BodyPose>& poses) {
  VecX u = VecX::Zero(3 * model.num_body_points);
  for (std::size_t k = 0; k < model.bodies.size(); ++k) {
    const BodyModel& body = model.bodies[k];
    if (body.motion == BodyMotion::kFree) continue;
    for (int j = 0; j < body.num_points(); ++j)
      u.segment<3>(3 * (body.point_offset + j)) =
          body.velocity + body.angular_velocity.cross(poses[k].rotation * body.surface.col(j));
  }
  return u;
}

Vec6 BodyVelocity(const Model& model, int k, const VecX& f) {
  const BodyModel& body = model.bodies[static_cast<size_t>(k)];
  if (body.motion != BodyMotion::kFree) {
    Vec6 v;
    v << body.velocity, body.angular_velocity;
    return v;
  }
  SR_ASSERT(f.size() == model.hydro_size(), "BodyVelocity: unknown of the wrong size");
  return f.segment<6>(3 * model.num_hydro_points() + 6 * body.free_index);
}

void AdvanceBodies(const Model& model, double h, const VecX& f, std::vector<BodyPose>* poses) {
  for (int k = 0; k < static_cast<int>(model.bodies.size()); ++k) {
    const Vec6 v = BodyVelocity(model, k, f);
    BodyPose& pose = (*poses)[static_cast<size_t>(k)];
    pose.center += h * v.head<3>();
    const double angle = h * v.tail<3>().norm();
    if (angle > 0.0)
      pose.rotation = Eigen::AngleAxisd(angle, v.tail<3>().normalized()).toRotationMatrix() *
                      pose.rotation;
  }
}

Vec6 BodyHydroLoad(const Model& model, int k, const BodyPose& pose, const VecX& f) {
  SR_ASSERT(f.size() == model.hydro_size(), "BodyHydroLoad: unknown of the wrong size");
  const BodyModel& body = model.bodies[static_cast<size_t>(k)];
  Vec6 load = Vec6::Zero();
  for (int j = 0; j < body.num_points(); ++j) {
    const Vec3 fj = f.segment<3>(3 * (model.num_nodes + body.point_offset + j));
    load.head<3>() += fj;
    load.tail<3>() += (pose.rotation * body.surface.col(j)).cross(fj);
  }
  return load;
}

}  // namespace stokesrods
