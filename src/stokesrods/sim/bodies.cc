#include "stokesrods/sim/bodies.h"

#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/rod/frames.h"

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

namespace {

// c ← c + hU, R ← exp(h[Ω]×)R.
void AdvanceBody(const Vec6& v, double h, BodyPose* pose) {
  pose->center += h * v.head<3>();
  const double angle = h * v.tail<3>().norm();
  if (angle > 0.0)
    pose->rotation = Eigen::AngleAxisd(angle, v.tail<3>().normalized()).toRotationMatrix() *
                     pose->rotation;
}

}  // namespace

void AdvanceBodies(const Model& model, double h, const VecX& f, std::vector<BodyPose>* poses) {
  for (int k = 0; k < static_cast<int>(model.bodies.size()); ++k)
    AdvanceBody(BodyVelocity(model, k, f), h, &(*poses)[static_cast<size_t>(k)]);
}

BodyPose Bdf2StartPose(const BodyPose& current, const BodyPose& previous) {
  BodyPose start;
  start.center = (4.0 * current.center - previous.center) / 3.0;
  const Eigen::AngleAxisd back(Mat3(previous.rotation * current.rotation.transpose()));
  start.rotation = Eigen::AngleAxisd(-back.angle() / 3.0, back.axis()).toRotationMatrix() *
                   current.rotation;
  return start;
}

void EndPoses(const Model& model, const BodyStep& step, const VecX& f,
              std::vector<BodyPose>* poses) {
  *poses = step.current;
  for (int k = 0; k < static_cast<int>(model.bodies.size()); ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (model.bodies[i].motion == BodyMotion::kFree)
      (*poses)[i] = step.start[i], AdvanceBody(BodyVelocity(model, k, f), step.he, &(*poses)[i]);
    else
      AdvanceBody(BodyVelocity(model, k, f), step.h, &(*poses)[i]);
  }
}

namespace {

// Moves rod's clamp (nodes and θ0) rigidly with its body from pose `from` to `to`.
void MoveClamp(const RodModel& rod, const BodyPose& from, const BodyPose& to, VecX* q) {
  const Mat3 turn = to.rotation * from.rotation.transpose();
  if (turn == Mat3::Identity() && to.center == from.center) return;
  const Vec3 t_old = (q->segment<3>(rod.dof_offset + NodeDof(1)) -
                      q->segment<3>(rod.dof_offset + NodeDof(0))).normalized();
  for (int i = 0; i < rod.clamped_nodes; ++i) {
    auto x = q->segment<3>(rod.dof_offset + NodeDof(i));
    x = to.center + turn * (Vec3(x) - from.center);
  }
  if (rod.clamped_nodes < 2) return;
  const Vec3 t_new = turn * t_old, u = t_old.unitOrthogonal();
  const Vec3 transported = ParallelTransport(u, t_old, t_new), turned = turn * u;
  (*q)(rod.dof_offset + TwistDof(0)) +=
      std::atan2(t_new.dot(transported.cross(turned)), transported.dot(turned));
}

}  // namespace

void DriveBodyClamps(const Model& model, const std::vector<BodyPose>& from,
                     const std::vector<BodyPose>& to, VecX* q) {
  for (const RodModel& rod : model.rods)
    if (rod.body >= 0)
      MoveClamp(rod, from[static_cast<std::size_t>(rod.body)],
                to[static_cast<std::size_t>(rod.body)], q);
}

void PlaceFreeClamps(const Model& model, const BodyStep& step, const VecX& f, VecX* q) {
  std::vector<BodyPose> next;
  EndPoses(model, step, f, &next);
  for (const RodModel& rod : model.rods) {
    if (rod.body < 0 || model.bodies[static_cast<std::size_t>(rod.body)].motion != BodyMotion::kFree)
      continue;
    for (int k : rod.fixed_dofs) (*q)(rod.dof_offset + k) = step.current_q(rod.dof_offset + k);
    if (rod.clamped_nodes >= 2) (*q)(rod.dof_offset + TwistDof(0)) += step.h * rod.twist_rate;
    const auto k = static_cast<std::size_t>(rod.body);
    MoveClamp(rod, step.current[k], next[k], q);
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
