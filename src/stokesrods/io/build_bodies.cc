#include "stokesrods/io/build_bodies.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "stokesrods/fluid/rigid_body.h"

namespace stokesrods {
namespace {

// Distance from p to the segment a–b [m].
double PointSegmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 v = b - a;
  const double t = std::clamp((p - a).dot(v) / v.squaredNorm(), 0.0, 1.0);
  return (p - a - t * v).norm();
}

void CheckWall(const Config& config, const Model& model) {
  if (!config.wall) return;
  const WallConfig& wall = *config.wall;
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodModel& rod = model.rods[r];
    for (int i = 0; i < rod.num_nodes(); ++i) {
      const double height = (rod.rest_positions.col(i) - wall.point).dot(wall.normal);
      if (height <= rod.radius)
        throw ConfigError(config.file, fmt::format("rods.{}.base", r + 1),
                          fmt::format("rod {} crosses or touches the wall: node {} is {:.4g} m "
                                      "above it, not more than the radius {:.4g} m",
                                      r + 1, i, height, rod.radius));
    }
  }
  for (std::size_t k = 0; k < config.bodies.size(); ++k) {
    const BodyConfig& body = config.bodies[k];
    const double height = (body.center - wall.point).dot(wall.normal);
    if (height <= body.radius)
      throw ConfigError(config.file, fmt::format("bodies.{}.center", k + 1),
                        fmt::format("body {} crosses or touches the wall: its centre is {:.4g} m "
                                    "above it, not more than its radius {:.4g} m",
                                    k + 1, height, body.radius));
  }
}

void CheckRodAgainstBody(const Config& config, const Model& model, std::size_t r, std::size_t k) {
  const RodModel& rod = model.rods[r];
  const BodyConfig& body = config.bodies[k];
  const Matrix3X& x = rod.rest_positions;
  const bool attached = config.rods[r].body == static_cast<int>(k + 1);
  if (attached) {
    const double gap = (x.col(0) - body.center).norm() - body.radius;
    if (std::abs(gap) > rod.rest_edge_length(0))
      throw ConfigError(config.file, fmt::format("rods.{}.base", r + 1),
                        fmt::format("rod {} is on body {} but its node 0 is {:.4g} m from the "
                                    "body's surface, more than its first edge ({:.4g} m)",
                                    r + 1, k + 1, gap, rod.rest_edge_length(0)));
  }
  // An attached rod's clamped edge starts at the surface; the rest must stay outside.
  const int first = attached ? 1 : 0;
  for (int i = first; i + 1 < rod.num_nodes(); ++i) {
    const double d = PointSegmentDistance(body.center, x.col(i), x.col(i + 1));
    if (d < body.radius + rod.radius)
      throw ConfigError(config.file, fmt::format("rods.{}.base", r + 1),
                        fmt::format("rod {} enters body {} at the start: its edge {} passes "
                                    "{:.4g} m from the centre, less than radius + r0 = {:.4g} m",
                                    r + 1, k + 1, i, d, body.radius + rod.radius));
  }
}

}  // namespace

void CheckBodiesAndWall(const Config& config, const Model& model) {
  CheckWall(config, model);
  for (std::size_t a = 0; a < config.bodies.size(); ++a)
    for (std::size_t b = a + 1; b < config.bodies.size(); ++b) {
      const double d = (config.bodies[a].center - config.bodies[b].center).norm();
      if (d <= config.bodies[a].radius + config.bodies[b].radius)
        throw ConfigError(config.file, fmt::format("bodies.{}.center", b + 1),
                          fmt::format("body {} overlaps body {}: their centres are {:.4g} m apart, "
                                      "not more than the sum of their radii {:.4g} m",
                                      b + 1, a + 1, d,
                                      config.bodies[a].radius + config.bodies[b].radius));
    }
  for (std::size_t r = 0; r < model.rods.size(); ++r)
    for (std::size_t k = 0; k < config.bodies.size(); ++k) CheckRodAgainstBody(config, model, r, k);
}

void AddBodies(const Config& config, Model* model) {
  for (const BodyConfig& bc : config.bodies) {
    BodyModel body;
    // A spheroid's scales and the start's overlap checks take its largest semi-axis (conservative).
    body.radius = bc.shape == "spheroid" ? std::max(bc.radius, bc.half_length) : bc.radius;
    body.center = bc.center;
    body.motion = bc.motion == "prescribed" ? BodyMotion::kPrescribed
                  : bc.motion == "free"     ? BodyMotion::kFree
                                            : BodyMotion::kFixed;
    body.velocity = bc.velocity;
    body.angular_velocity = bc.angular_velocity;
    body.force = bc.force;
    body.torque = bc.torque;
    const BodySurface surface =
        bc.shape == "spheroid"
            ? SpheroidSurface(Vec3::Zero(), bc.radius, bc.half_length, bc.axis, bc.surface_points,
                              kBodyBlobOverSpacing)
            : SphereSurface(Vec3::Zero(), bc.radius, bc.surface_points, kBodyBlobOverSpacing);
    body.surface = surface.points;
    body.regularization = surface.regularization;
    model->bodies.push_back(std::move(body));
  }
}

}  // namespace stokesrods
