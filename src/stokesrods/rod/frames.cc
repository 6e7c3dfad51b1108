#include "stokesrods/rod/frames.h"

#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/rod/frame_columns.h"

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

namespace {

// The lanes' pass of TransportFramesAndTwists on `path`, or false where the path is not this
// CPU's or the input is degenerate (the portable functions then say how).
bool TransportFramesInLanes(const Matrix3X& x_new, std::vector<Vec3>* tangents,
                            std::vector<RefFrame>* frames, const VecX& previous_twist,
                            VecX* twist, FramePath path) {
#if defined(__x86_64__)
  static const bool has_avx512 = __builtin_cpu_supports("avx512f");
  static const bool has_avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  const bool avx512 = path == FramePath::kWidest && has_avx512;
  if (!avx512 && (path == FramePath::kPortable || !has_avx2)) return false;
  const Eigen::Index nodes = x_new.cols();
  const auto edges = static_cast<std::size_t>(nodes - 1);
  if (nodes < 2 || tangents->size() != edges || frames->size() != edges ||
      (previous_twist.size() != 0 && previous_twist.size() != nodes))
    return false;
  // Columns: x (3 × nodes), then 3 each of the old tangents, old d1, tangents, d1, d2, and the
  // angles (edges each). Kept: no allocation per call.
  thread_local std::vector<double> scratch;
  const auto n = static_cast<std::size_t>(nodes);
  scratch.resize(3 * n + 16 * edges);
  FrameColumns c;
  double* next = scratch.data();
  for (int k = 0; k < 3; ++k, next += n) {
    for (std::size_t i = 0; i < n; ++i) next[i] = x_new(k, static_cast<Eigen::Index>(i));
    c.x[k] = next;
  }
  for (int k = 0; k < 3; ++k, next += edges) {
    for (std::size_t j = 0; j < edges; ++j) next[j] = (*tangents)[j][k];
    c.old_tangent[k] = next;
  }
  for (int k = 0; k < 3; ++k, next += edges) {
    for (std::size_t j = 0; j < edges; ++j) next[j] = (*frames)[j].d1[k];
    c.old_d1[k] = next;
  }
  for (int k = 0; k < 3; ++k) c.tangent[k] = next, next += edges;
  for (int k = 0; k < 3; ++k) c.d1[k] = next, next += edges;
  for (int k = 0; k < 3; ++k) c.d2[k] = next, next += edges;
  c.angle = next;
  const int count = static_cast<int>(edges);
  if (avx512)
    TransportFrameLanesAvx512(count, &c);
  else
    TransportFrameLanesAvx2(count, &c);
  // The portable functions' checks (EdgeTangents, ParallelTransport, OrthonormalFrame).
  if (!(c.smallest[0] > 0.0 && c.smallest[1] > 1e-12 && c.smallest[2] > 1e-8)) return false;
  for (std::size_t i = 0; i + 1 < edges; ++i)
    if (!std::isfinite(c.angle[i])) return false;
  for (std::size_t j = 0; j < edges; ++j)  // a NaN anywhere reaches d1 (the minima skip NaN)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(c.d1[k][j])) return false;
  for (std::size_t j = 0; j < edges; ++j)
    for (int k = 0; k < 3; ++k) {
      (*tangents)[j][k] = c.tangent[k][j];
      (*frames)[j].d1[k] = c.d1[k][j];
      (*frames)[j].d2[k] = c.d2[k][j];
    }
  twist->setZero(nodes);
  const double two_pi = 2.0 * kPi;
  for (Eigen::Index i = 1; i + 1 < nodes; ++i) {  // as ReferenceTwist's
    const double angle = c.angle[i - 1];
    const double previous = previous_twist.size() == 0 ? 0.0 : previous_twist[i];
    (*twist)[i] = angle + two_pi * std::round((previous - angle) / two_pi);
  }
  return true;
#else
  (void)x_new, (void)tangents, (void)frames, (void)previous_twist, (void)twist, (void)path;
  return false;
#endif
}

}  // namespace

void TransportFramesAndTwists(const Matrix3X& x_new, std::vector<Vec3>* tangents,
                              std::vector<RefFrame>* frames, const VecX& previous_twist,
                              VecX* twist, FramePath path) {
  if (TransportFramesInLanes(x_new, tangents, frames, previous_twist, twist, path)) return;
  TransportFramesInTime(x_new, tangents, frames);
  *twist = ReferenceTwists(*frames, *tangents, previous_twist);
}

void MaterialFrame(const RefFrame& f, double theta, Vec3* m1, Vec3* m2) {
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  *m1 = c * f.d1 + s * f.d2;
  *m2 = -s * f.d1 + c * f.d2;
}

}  // namespace stokesrods
