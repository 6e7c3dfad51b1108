// Checks of [[bodies]], [wall] and the rods' `body` key (SPEC "Additions") whose types are already
// right; the geometric checks that need the rods' shapes (overlaps, the wall crossing) are in
// build_bodies.cc.
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "stokesrods/io/config.h"

namespace stokesrods {
namespace {

void CheckFinite(const std::string& file, const std::string& key, const Vec3& v) {
  if (!v.allFinite()) throw ConfigError(file, key, "must be finite");
}

// A spheroid: its semi-axis and axis; no contact and no rods on it yet (both assume a sphere).
void ValidateSpheroid(const Config& config, const std::string& p, int k, BodyConfig* body) {
  const std::string& file = config.file;
  if (body->shape == "sphere") {
    if (body->half_length != 0.0 || body->axis != Vec3::UnitZ())
      throw ConfigError(file, p + (body->half_length != 0.0 ? ".half_length" : ".axis"),
                        "only for shape = \"spheroid\"");
    return;
  }
  if (!(body->half_length > 0.0) || !std::isfinite(body->half_length))
    throw ConfigError(file, p + ".half_length",
                      fmt::format("a spheroid needs a finite polar semi-axis > 0 (got {})", body->half_length));
  CheckFinite(file, p + ".axis", body->axis);
  if (!(body->axis.norm() > 0.0)) throw ConfigError(file, p + ".axis", "must not be the zero vector");
  body->axis.normalize();
  if (config.contact.enabled)
    throw ConfigError(file, p + ".shape",
                      "a \"spheroid\" takes no contact yet (contact assumes spheres); set "
                      "contact.enabled = false");
  for (std::size_t r = 0; r < config.rods.size(); ++r)
    if (config.rods[r].body == k + 1)
      throw ConfigError(file, fmt::format("rods.{}.body", r + 1),
                        fmt::format("body {} is a spheroid: rods are clamped on spheres only yet", k + 1));
}

void ValidateBody(const Config& config, const std::string& p, const BodyConfig& body) {
  const std::string& file = config.file;
  if (body.shape != "sphere" && body.shape != "spheroid")
    throw ConfigError(file, p + ".shape",
                      fmt::format("\"{}\" is not one of \"sphere\", \"spheroid\"", body.shape));
  if (!(body.radius > 0.0) || !std::isfinite(body.radius))
    throw ConfigError(file, p + ".radius", fmt::format("must be a finite number > 0 (got {})", body.radius));
  CheckFinite(file, p + ".center", body.center);
  CheckFinite(file, p + ".velocity", body.velocity);
  CheckFinite(file, p + ".angular_velocity", body.angular_velocity);
  CheckFinite(file, p + ".force", body.force);
  CheckFinite(file, p + ".torque", body.torque);
  static const std::set<std::string> kMotions = {"fixed", "free", "prescribed"};
  if (kMotions.count(body.motion) == 0)
    throw ConfigError(file, p + ".motion",
                      fmt::format("\"{}\" is not one of \"fixed\", \"free\", \"prescribed\"", body.motion));
  if (body.motion != "prescribed" && (body.velocity != Vec3::Zero() || body.angular_velocity != Vec3::Zero()))
    throw ConfigError(file, p + (body.velocity != Vec3::Zero() ? ".velocity" : ".angular_velocity"),
                      "only for motion = \"prescribed\"");
  if (body.motion != "free" && (body.force != Vec3::Zero() || body.torque != Vec3::Zero()))
    throw ConfigError(file, p + (body.force != Vec3::Zero() ? ".force" : ".torque"),
                      "only for motion = \"free\" (fixed and prescribed bodies take any load)");
  if (body.surface_points < 20 || body.surface_points > 20000)
    throw ConfigError(file, p + ".surface_points",
                      fmt::format("must be between 20 and 20000 (got {})", body.surface_points));
  if (config.fluid.model != "rss")
    throw ConfigError(file, p, fmt::format("bodies need fluid.model = \"rss\" (got \"{}\")",
                                           config.fluid.model));
  if (config.fluid.coupling == "explicit")
    throw ConfigError(file, "fluid.coupling", "bodies need fluid.coupling = \"implicit\"");
}

void ValidateWall(Config* config) {
  const std::string& file = config->file;
  WallConfig& wall = *config->wall;
  CheckFinite(file, "wall.point", wall.point);
  CheckFinite(file, "wall.normal", wall.normal);
  if (!(wall.normal.norm() > 0.0))
    throw ConfigError(file, "wall.normal", "must not be the zero vector");
  wall.normal.normalize();
  const std::string& model = config->fluid.model;
  if (model != "rss")
    throw ConfigError(file, "wall",
                      fmt::format("fluid.model = \"{}\" has no wall: a wall acts through the "
                                  "regularized images of fluid.model = \"rss\" (no wall "
                                  "correction of LSBT or RFT)",
                                  model));
}

}  // namespace

void ValidateBodiesAndWall(Config* config) {
  for (std::size_t k = 0; k < config->bodies.size(); ++k) {
    const std::string p = fmt::format("bodies.{}", k + 1);
    ValidateBody(*config, p, config->bodies[k]);
    ValidateSpheroid(*config, p, static_cast<int>(k), &config->bodies[k]);
  }
  if (config->wall) ValidateWall(config);
  for (std::size_t r = 0; r < config->rods.size(); ++r) {
    const RodConfig& rod = config->rods[r];
    const std::string key = fmt::format("rods.{}.body", r + 1);
    if (rod.body == 0) continue;
    if (rod.body < 0 || rod.body > static_cast<int>(config->bodies.size()))
      throw ConfigError(config->file, key,
                        fmt::format("body {} does not exist (there are {} [[bodies]])", rod.body,
                                    config->bodies.size()));
    if (rod.clamped_nodes < 1)
      throw ConfigError(config->file, key, "a rod on a body needs clamped_nodes ≥ 1");
  }
}

}  // namespace stokesrods
