// Basic linear-algebra types used throughout stokesrods.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace stokesrods {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;
template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int N>
using Mat = Eigen::Matrix<double, N, N>;
using Vec6 = Vec<6>;
using Mat6 = Mat<6>;
using Vec11 = Vec<11>;
using Mat11 = Mat<11>;
/// Node positions of one rod, one node per column (3 × N).
using Matrix3X = Eigen::Matrix<double, 3, Eigen::Dynamic>;

constexpr double kPi = 3.14159265358979323846;

/// [a]×, the cross product's matrix: [a]× b = a × b.
inline Mat3 CrossMatrix(const Vec3& a) {
  Mat3 m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

}  // namespace stokesrods
