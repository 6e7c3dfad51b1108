#include "stokesrods/io/rest_shape.h"

#include <cmath>

#include <fmt/format.h>

#include "stokesrods/rod/geometry.h"

namespace stokesrods {

Matrix3X RestShape(const RodConfig& rod) {
  if (rod.shape == "straight") return StraightNodes(rod.nodes, rod.axis_length, rod.base);
  if (rod.shape == "points") {
    Matrix3X x(3, static_cast<Eigen::Index>(rod.points.size()));
    for (std::size_t i = 0; i < rod.points.size(); ++i) x.col(static_cast<Eigen::Index>(i)) = rod.points[i];
    return x;
  }
  HelixGeometry g;
  g.nodes = rod.nodes;
  g.axis_length = rod.axis_length;
  g.pitch = rod.pitch;
  g.helix_radius = rod.helix_radius;
  g.right_handed = rod.handedness == "right";
  g.lead_in_above = rod.lead_in == "above";
  g.base = rod.base;
  return HelixNodes(g);
}

void CheckRestShape(const std::string& file, const std::string& key, const RodConfig& rod,
                    const Matrix3X& x) {
  const bool points = rod.shape == "points";
  // A generated shape's coordinates come from its base and its size; a points rod's from point i.
  // (the base when it carries at least half of the coordinate at fault).
  auto key_of = [&](Eigen::Index i, double coordinate) {
    if (points) return fmt::format("{}.points[{}]", key, i);
    return key + (rod.base.lpNorm<Eigen::Infinity>() >= 0.5 * coordinate ? ".base" : ".axis_length");
  };
  for (Eigen::Index i = 0; i < x.cols(); ++i)
    if (!x.col(i).allFinite() || x.col(i).lpNorm<Eigen::Infinity>() > kMaxCoordinate)
      throw ConfigError(file, key_of(i, x.col(i).lpNorm<Eigen::Infinity>()),
                        fmt::format("node {} at ({}, {}, {}) lies outside ±{:g} m", i, x(0, i),
                                    x(1, i), x(2, i), kMaxCoordinate));
  Eigen::Index farthest = 0;
  const double reach = x.colwise().lpNorm<Eigen::Infinity>().maxCoeff(&farthest);
  for (Eigen::Index i = 0; i + 1 < x.cols(); ++i) {
    const double edge = (x.col(i + 1) - x.col(i)).norm();
    if (!(edge * kMaxPositionOverEdge >= reach))
      throw ConfigError(
          file, key_of(farthest, reach),
          fmt::format("node {} lies {:.4g} m from the origin, more than {:g} times edge {} "
                      "({:.4g} m): the edges would keep fewer than 8 significant digits",
                      farthest, reach, kMaxPositionOverEdge, i, edge));
  }
  for (Eigen::Index i = 1; i + 1 < x.cols(); ++i) {
    // A 180° turn has no curvature binormal (2 t0 × t1 / (1 + t0 · t1)) and no parallel
    // transport of the frame: the edges before and after node i must not be opposite.
    const Vec3 t0 = (x.col(i) - x.col(i - 1)).normalized();
    const Vec3 t1 = (x.col(i + 1) - x.col(i)).normalized();
    if (t0.dot(t1) <= -1.0 + 1e-9)
      throw ConfigError(file, key_of(i + 1, HUGE_VAL),
                        fmt::format("turns the rod back on itself (a 180° turn at node {})", i));
  }
}

}  // namespace stokesrods
