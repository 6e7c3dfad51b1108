#include "stokesrods/sim/body_contact.h"

#include <algorithm>

namespace stokesrods {

namespace {

bool IsFree(const Model& model, int k) {
  return k >= 0 && model.bodies[static_cast<std::size_t>(k)].motion == BodyMotion::kFree;
}

double Radius(const Model& model, int k) { return model.bodies[static_cast<std::size_t>(k)].radius; }

// The surface point of body k facing along `outward` (unit, from its centre).
Vec3 SurfacePoint(const Model& model, int k, const std::vector<BodyPose>& poses,
                  const Vec3& outward) {
  return poses[static_cast<std::size_t>(k)].center + Radius(model, k) * outward;
}

}  // namespace

std::vector<BodyPair> DetectBodyContacts(const Model& model, const std::vector<BodyPose>& poses) {
  std::vector<BodyPair> pairs;
  const int n = static_cast<int>(model.bodies.size());
  for (int a = 0; a < n; ++a) {
    const Vec3 ca = poses[static_cast<std::size_t>(a)].center;
    if (model.fluid.wall && IsFree(model, a)) {
      const Wall& wall = *model.fluid.wall;
      const double d = wall.normal.dot(ca - wall.point);
      if (d < Radius(model, a)) pairs.push_back({a, -1, wall.normal, Radius(model, a) - d, Radius(model, a)});
    }
    for (int b = a + 1; b < n; ++b) {
      if (!IsFree(model, a) && !IsFree(model, b)) continue;
      const Vec3 gap = ca - poses[static_cast<std::size_t>(b)].center;
      const double reach = Radius(model, a) + Radius(model, b), d = gap.norm();
      if (d < reach) pairs.push_back({a, b, gap / d, reach - d, reach});
    }
  }
  return pairs;
}

void AddBodyPairLoads(const Model& model, const BodyPair& pair, double magnitude,
                      const std::vector<BodyPose>& poses, VecX* loads) {
  auto add = [&](int k, const Vec3& force) {
    if (!IsFree(model, k) || magnitude == 0.0) return;
    const BodyModel& body = model.bodies[static_cast<std::size_t>(k)];
    const Vec3 arm = SurfacePoint(model, k, poses, -force.normalized()) -
                     poses[static_cast<std::size_t>(k)].center;
    loads->segment<3>(6 * body.free_index) += force;
    loads->segment<3>(6 * body.free_index + 3) += arm.cross(force);
  };
  add(pair.body, magnitude * pair.normal);
  add(pair.other, -magnitude * pair.normal);
}

double BodyPairTrialForce(const Model& model, const BodyPair& pair, double h) {
  double a = Radius(model, pair.body);
  if (pair.other >= 0) a = std::min(a, Radius(model, pair.other));
  return 6.0 * kPi * model.fluid.viscosity * a * pair.penetration / h;
}

Vec3 BodyPointShift(const Model& model, int k, const std::vector<BodyPose>& poses,
                    const Vec3& x, double h, const VecX& dv) {
  if (!IsFree(model, k)) return Vec3::Zero();
  const Vec6 v = dv.segment<6>(6 * model.bodies[static_cast<std::size_t>(k)].free_index);
  return h * (v.head<3>() + v.tail<3>().cross(x - poses[static_cast<std::size_t>(k)].center));
}

double BodyPairSeparationChange(const Model& model, const BodyPair& pair,
                                const std::vector<BodyPose>& poses, double h, const VecX& dv) {
  const Vec3 p_body = SurfacePoint(model, pair.body, poses, -pair.normal);
  Vec3 shift = BodyPointShift(model, pair.body, poses, p_body, h, dv);
  if (pair.other >= 0)
    shift -= BodyPointShift(model, pair.other, poses,
                            SurfacePoint(model, pair.other, poses, pair.normal), h, dv);
  return pair.normal.dot(shift);
}

}  // namespace stokesrods
