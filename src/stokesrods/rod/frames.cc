#include "stokesrods/rod/frames.h"

#include <cmath>

#include "stokesrods/common/assert.h"

namespace stokesrods {

namespace {

// Makes d1 exactly perpendicular to the unit tangent t and of unit length; d2 = t × d1.
RefFrame OrthonormalFrame(const Vec3& d1, const Vec3& t) {
  const Vec3 projected = d1 - d1.dot(t) * t;
  const double norm = projected.norm();
  SR_ASSERT(norm > 1e-8, "reference director d1 is (nearly) parallel to the tangent");
  RefFrame f;
  f.d1 = projected / norm;
  f.d2 = t.cross(f.d1);
  return f;
}

}  // namespace

Vec3 ParallelTransport(const Vec3& u, const Vec3& t0, const Vec3& t1) {
  // Rodrigues' rotation about b = t0 × t1 (|b| = sin φ, c = cos φ), written without dividing by
  // |b| so that it is exact (the identity) when t0 = t1:
  //   R u = c u + b × u + (b · u) b / (1 + c).
  const Vec3 b = t0.cross(t1);
  const double c = t0.dot(t1);
  SR_ASSERT(c > -1.0 + 1e-12, "parallel transport between opposite tangents is undefined");
  return c * u + b.cross(u) + (b.dot(u) / (1.0 + c)) * b;
}

double SignedAngle(const Vec3& u, const Vec3& v, const Vec3& n) {
  return std::atan2(u.cross(v).dot(n), u.dot(v));
}

Vec3 AnyPerpendicular(const Vec3& t) {
  // Cross t with the coordinate axis it is least aligned with: never degenerate.
  Eigen::Index axis = 0;
  t.cwiseAbs().minCoeff(&axis);
  return t.cross(Vec3::Unit(axis)).normalized();
}

std::vector<Vec3> EdgeTangents(const Matrix3X& x) {
  SR_ASSERT(x.cols() >= 2, "a rod needs at least 2 nodes");
  std::vector<Vec3> tangents(static_cast<size_t>(x.cols() - 1));
  for (Eigen::Index i = 0; i + 1 < x.cols(); ++i) {
    const Vec3 e = x.col(i + 1) - x.col(i);
    const double length = e.norm();
    SR_ASSERT(length > 0.0, "zero-length edge");
    tangents[static_cast<size_t>(i)] = e / length;
  }
  return tangents;
}

std::vector<RefFrame> SpaceParallelFrames(const Matrix3X& x, const Vec3* first_d1) {
  const std::vector<Vec3> t = EdgeTangents(x);
  std::vector<RefFrame> frames(t.size());
  frames[0] = OrthonormalFrame(first_d1 ? *first_d1 : AnyPerpendicular(t[0]), t[0]);
  for (size_t i = 1; i < t.size(); ++i) {
    frames[i] = OrthonormalFrame(ParallelTransport(frames[i - 1].d1, t[i - 1], t[i]), t[i]);
  }
  return frames;
}

void TransportFramesInTime(const Matrix3X& x_new, std::vector<Vec3>* old_tangents,
                           std::vector<RefFrame>* frames) {
  const std::vector<Vec3> t = EdgeTangents(x_new);
  SR_ASSERT(old_tangents->size() == t.size() && frames->size() == t.size(),
            "frames, tangents and positions disagree on the number of edges");
  for (size_t i = 0; i < t.size(); ++i) {
    // Re-orthonormalising after the rotation removes round-off drift over many steps; the change
    // is at the level of machine precision, so the transport is unaffected.
    (*frames)[i] = OrthonormalFrame(ParallelTransport((*frames)[i].d1, (*old_tangents)[i], t[i]),
                                    t[i]);
  }
  *old_tangents = t;
}

double ReferenceTwist(const RefFrame& f0, const Vec3& t0, const RefFrame& f1, const Vec3& t1,
                      double previous) {
  const Vec3 transported = ParallelTransport(f0.d1, t0, t1);
  const double angle = SignedAngle(transported, f1.d1, t1);  // in (−π, π]
  const double two_pi = 2.0 * kPi;
  return angle + two_pi * std::round((previous - angle) / two_pi);
}

VecX ReferenceTwists(const std::vector<RefFrame>& frames, const std::vector<Vec3>& tangents,
                     const VecX& previous) {
  SR_ASSERT(frames.size() == tangents.size(), "one frame per edge tangent");
  const Eigen::Index nodes = static_cast<Eigen::Index>(frames.size()) + 1;
  SR_ASSERT(previous.size() == 0 || previous.size() == nodes, "previous: one value per node");
  VecX twist = VecX::Zero(nodes);
  for (Eigen::Index i = 1; i + 1 < nodes; ++i) {
    const size_t e = static_cast<size_t>(i);
    const double prev = previous.size() == 0 ? 0.0 : previous[i];
    twist[i] = ReferenceTwist(frames[e - 1], tangents[e - 1], frames[e], tangents[e], prev);
  }
  return twist;
}

void MaterialFrame(const RefFrame& f, double theta, Vec3* m1, Vec3* m2) {
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  *m1 = c * f.d1 + s * f.d2;
  *m2 = -s * f.d1 + c * f.d2;
}

}  // namespace stokesrods
