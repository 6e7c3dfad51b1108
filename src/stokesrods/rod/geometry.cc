#include "stokesrods/rod/geometry.h"

#include <cmath>

#include "stokesrods/common/assert.h"

namespace stokesrods {

Matrix3X HelixNodes(const HelixGeometry& g) {
  SR_ASSERT(g.nodes >= 4, "a helix needs at least 4 nodes");
  const int n = g.nodes;
  const double R = g.helix_radius;
  const double c = std::sqrt(1.0 + std::pow(2.0 * kPi * R / g.pitch, 2));
  // a = Δs (the helical arc spacing); Δs = c · helix_drop / (N − 3).
  const double first_edge = g.lead_in_above ? g.axis_length * c / (n - 3)
                                            : (g.axis_length - R) * c / (n - 3 + c);
  const double helix_drop = g.lead_in_above ? g.axis_length : g.axis_length - first_edge - R;
  const double sign = g.right_handed ? -1.0 : 1.0;           // y = ∓R sin φ
  Matrix3X x(3, n);
  x.col(0) = g.base;
  x.col(1) = g.base - first_edge * Vec3::UnitZ();
  const double z2 = -first_edge - R;
  for (int i = 2; i < n; ++i) {
    const double drop = helix_drop * (i - 2) / (n - 3);  // even in arc length: arc ∝ drop
    const double phi = 2.0 * kPi * drop / g.pitch;
    x.col(i) = g.base + Vec3(R * std::cos(phi), sign * R * std::sin(phi), z2 - drop);
  }
  return x;
}

Matrix3X StraightNodes(int nodes, double axis_length, const Vec3& base) {
  SR_ASSERT(nodes >= 2, "a rod needs at least 2 nodes");
  Matrix3X x(3, nodes);
  for (int i = 0; i < nodes; ++i) {
    x.col(i) = base - axis_length * i / (nodes - 1) * Vec3::UnitZ();
  }
  return x;
}

}  // namespace stokesrods
