#include "stokesrods/rod/frames.h"

#include <gtest/gtest.h>

#include <Eigen/LU>  // determinant

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "stokesrods/rod/geometry.h"

namespace stokesrods {
namespace {

Vec3 RandomUnit(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return Vec3(normal(rng), normal(rng), normal(rng)).normalized();
}

// Rotation of u about the unit axis n by angle a (Rodrigues).
Vec3 Rotate(const Vec3& u, const Vec3& n, double a) {
  return std::cos(a) * u + std::sin(a) * n.cross(u) + (1.0 - std::cos(a)) * n.dot(u) * n;
}

// Largest deviation of {d1, d2, t} from a right-handed orthonormal frame.
double OrthonormalityError(const RefFrame& f, const Vec3& t) {
  Mat3 q;
  q << f.d1, f.d2, t;
  const double det_error = std::abs(q.determinant() - 1.0);
  return std::max((q.transpose() * q - Mat3::Identity()).cwiseAbs().maxCoeff(), det_error);
}

TEST(ParallelTransport, MapsT0ToT1AndPreservesAngles) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 100; ++trial) {
    const Vec3 t0 = RandomUnit(rng);
    Vec3 t1 = RandomUnit(rng);
    if (t0.dot(t1) < -0.9) t1 = -t1;
    EXPECT_LT((ParallelTransport(t0, t0, t1) - t1).norm(), 1e-14);
    const Vec3 u = RandomUnit(rng);
    const Vec3 v = 2.0 * RandomUnit(rng);
    const Vec3 pu = ParallelTransport(u, t0, t1);
    const Vec3 pv = ParallelTransport(v, t0, t1);
    EXPECT_NEAR(pu.dot(pv), u.dot(v), 1e-14);
    EXPECT_NEAR(pv.norm(), 2.0, 1e-14);
    EXPECT_NEAR(pu.cross(pv).dot(t1), u.cross(v).dot(t0), 1e-14);  // orientation kept
    // The binormal, normal to both tangents, is the rotation axis: it is left alone.
    const Vec3 b = t0.cross(t1).normalized();
    EXPECT_LT((ParallelTransport(b, t0, t1) - b).norm(), 1e-14);
  }
  const Vec3 t = RandomUnit(rng);
  const Vec3 u = RandomUnit(rng);
  EXPECT_EQ(ParallelTransport(u, t, t), u);  // identity, exactly
}

TEST(SignedAngle, RightHandedAboutTheAxis) {
  EXPECT_NEAR(SignedAngle(Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()), kPi / 2, 1e-15);
  EXPECT_NEAR(SignedAngle(Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitZ()), -kPi / 2, 1e-15);
  EXPECT_NEAR(SignedAngle(Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitZ()), kPi, 1e-15);
  const Vec3 u = Rotate(Vec3::UnitX(), Vec3::UnitZ(), 2.5);
  EXPECT_NEAR(SignedAngle(u, Vec3::UnitX(), Vec3::UnitZ()), -2.5, 1e-14);
}

TEST(AnyPerpendicular, IsAUnitNormal) {
  std::mt19937 rng(2);
  for (const Vec3& t : {Vec3(Vec3::UnitX()), Vec3(Vec3::UnitZ()), RandomUnit(rng)}) {
    const Vec3 p = AnyPerpendicular(t);
    EXPECT_NEAR(p.norm(), 1.0, 1e-15);
    EXPECT_NEAR(p.dot(t), 0.0, 1e-15);
  }
}

TEST(SpaceParallelFrames, OrthonormalWithZeroReferenceTwist) {
  const Matrix3X x = HelixNodes(HelixGeometry{});
  const Vec3 first_d1(1.0, 2.0, 0.3);
  const std::vector<RefFrame> frames = SpaceParallelFrames(x, &first_d1);
  const std::vector<Vec3> t = EdgeTangents(x);
  ASSERT_EQ(frames.size(), static_cast<size_t>(x.cols() - 1));
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_LT(OrthonormalityError(frames[i], t[i]), 1e-14) << "edge " << i;
  }
  // d1 of edge 0 is first_d1 projected onto the plane normal to t^0.
  const Vec3 projected = (first_d1 - first_d1.dot(t[0]) * t[0]).normalized();
  EXPECT_LT((frames[0].d1 - projected).norm(), 1e-15);
  const VecX twist = ReferenceTwists(frames, t, VecX());
  ASSERT_EQ(twist.size(), x.cols());
  EXPECT_LT(twist.cwiseAbs().maxCoeff(), 1e-13);
  // Without first_d1 the frames are still space-parallel.
  EXPECT_LT(ReferenceTwists(SpaceParallelFrames(x), t, VecX()).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(TransportFramesInTime, StaysOrthonormalOverManySmallSteps) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  HelixGeometry g;
  g.nodes = 12;
  Matrix3X x = HelixNodes(g);
  std::vector<RefFrame> frames = SpaceParallelFrames(x);
  std::vector<Vec3> tangents = EdgeTangents(x);
  const double step = 5e-5;  // [m], ~1% of an edge per step
  for (int s = 0; s < 1000; ++s) {
    for (Eigen::Index i = 0; i < x.cols(); ++i) {
      x.col(i) += step * Vec3(normal(rng), normal(rng), normal(rng));
    }
    const std::vector<Vec3> old = tangents;
    const std::vector<RefFrame> before = frames;
    TransportFramesInTime(x, &tangents, &frames);
    for (size_t i = 0; i < frames.size(); ++i) {  // each step is one parallel transport
      ASSERT_LT((frames[i].d1 - ParallelTransport(before[i].d1, old[i], tangents[i])).norm(),
                1e-14);
    }
  }
  const std::vector<Vec3> t = EdgeTangents(x);
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_LT((tangents[i] - t[i]).norm(), 1e-15);
    EXPECT_LT(OrthonormalityError(frames[i], t[i]), 1e-12) << "edge " << i;
  }
}

TEST(TransportFramesInTime, OneStepIsTheParallelTransportOfEachFrame) {
  std::mt19937 rng(4);
  const Matrix3X x = HelixNodes(HelixGeometry{});
  std::vector<RefFrame> frames = SpaceParallelFrames(x);
  std::vector<Vec3> tangents = EdgeTangents(x);
  const std::vector<RefFrame> before = frames;
  const std::vector<Vec3> t_before = tangents;
  Matrix3X x_new = x;
  for (Eigen::Index i = 0; i < x.cols(); ++i) x_new.col(i) += 1e-3 * RandomUnit(rng);
  TransportFramesInTime(x_new, &tangents, &frames);
  for (size_t i = 0; i < frames.size(); ++i) {
    const Vec3 expected = ParallelTransport(before[i].d1, t_before[i], tangents[i]);
    EXPECT_LT((frames[i].d1 - expected).norm(), 1e-14);
    EXPECT_LT((frames[i].d2 - tangents[i].cross(expected)).norm(), 1e-14);
  }
}

TEST(ReferenceTwist, StraightRodWithFramesRotatedByAKnownAngle) {
  const Matrix3X x = StraightNodes(8, 0.1, Vec3::Zero());
  const std::vector<Vec3> t = EdgeTangents(x);
  const double alpha = 0.37;  // [rad] per edge
  std::vector<RefFrame> frames(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    frames[i].d1 = Rotate(Vec3::UnitX(), t[i], alpha * static_cast<double>(i));
    frames[i].d2 = t[i].cross(frames[i].d1);
  }
  const VecX twist = ReferenceTwists(frames, t, VecX());
  EXPECT_EQ(twist[0], 0.0);
  EXPECT_EQ(twist[7], 0.0);
  for (int i = 1; i < 7; ++i) EXPECT_NEAR(twist[i], alpha, 1e-14);
}

TEST(ReferenceTwist, HelixWithOneFrameRotated) {
  const Matrix3X x = HelixNodes(HelixGeometry{});
  std::vector<RefFrame> frames = SpaceParallelFrames(x);
  const std::vector<Vec3> t = EdgeTangents(x);
  const size_t k = 20;
  const double beta = -1.1;  // [rad]
  frames[k].d1 = Rotate(frames[k].d1, t[k], beta);
  frames[k].d2 = Rotate(frames[k].d2, t[k], beta);
  const VecX twist = ReferenceTwists(frames, t, VecX());
  for (Eigen::Index i = 0; i < twist.size(); ++i) {
    const double expected = i == 20 ? beta : (i == 21 ? -beta : 0.0);
    EXPECT_NEAR(twist[i], expected, 1e-13) << "node " << i;
  }
}

TEST(ReferenceTwist, PicksTheBranchClosestToPrevious) {
  const Vec3 t = Vec3::UnitZ();
  const RefFrame f0{Vec3::UnitX(), Vec3::UnitY()};
  auto frame_at = [&](double a) {
    return RefFrame{Rotate(Vec3::UnitX(), t, a), Rotate(Vec3::UnitY(), t, a)};
  };
  const double two_pi = 2.0 * kPi;
  EXPECT_NEAR(ReferenceTwist(f0, t, frame_at(0.3), t, 0.0), 0.3, 1e-14);
  EXPECT_NEAR(ReferenceTwist(f0, t, frame_at(0.3), t, 6.0), 0.3 + two_pi, 1e-14);
  EXPECT_NEAR(ReferenceTwist(f0, t, frame_at(0.3), t, -6.0), 0.3 - two_pi, 1e-14);
  EXPECT_NEAR(ReferenceTwist(f0, t, frame_at(0.3), t, 4.0 * two_pi), 0.3 + 4.0 * two_pi, 1e-13);
  // Across the ±π cut: an angle just past π stays continuous with a previous value near π.
  EXPECT_NEAR(ReferenceTwist(f0, t, frame_at(kPi + 0.01), t, 3.1), kPi + 0.01, 1e-14);
  EXPECT_NEAR(ReferenceTwist(f0, t, frame_at(kPi - 0.01), t, -3.1), -kPi - 0.01, 1e-14);
  // Winding up in small increments accumulates the full angle.
  double twist = 0.0;
  for (int s = 1; s <= 60; ++s) {
    const double angle = 0.4 * s;
    twist = ReferenceTwist(f0, t, frame_at(angle), t, twist);
    ASSERT_NEAR(twist, angle, 1e-12);
  }
}

// The lanes' pass (rod/frame_lanes.h: AVX-512, AVX2) against the portable one, the reference
// (TransportFramesInTime, then ReferenceTwists), on every path this CPU has (a path it lacks
// runs the next narrower, so each call is still checked): helices of 4 … 65 nodes (every count of
// spare lanes), moved by random steps of up to a fifth of an edge, with frames turned by up to π
// about their tangents and previous twists wound several times. Tolerances: frames and tangents
// 4e-15 (a few roundings of unit vectors); twists 4e-15 + 1e-15 |twist| (glibc's vector
// arctangent is within a few units in the last place of std::atan2, and the unwinding adds
// multiples of 2π).
TEST(FramesTest, TransportFramesAndTwistsOnEachPath) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  double worst_frame = 0.0, worst_twist = 0.0;
  for (FramePath path : {FramePath::kWidest, FramePath::kAvx2, FramePath::kPortable}) {
    for (int nodes : {4, 5, 6, 7, 8, 9, 10, 11, 12, 17, 33, 65}) {
      HelixGeometry g;
      g.nodes = nodes;
      const Matrix3X x = HelixNodes(g);
      const double edge = (x.col(1) - x.col(0)).norm();
      std::vector<RefFrame> frames = SpaceParallelFrames(x);
      std::vector<Vec3> tangents = EdgeTangents(x);
      for (std::size_t j = 0; j < frames.size(); ++j) {  // frames turned about their tangents
        const double a = kPi * uniform(rng);
        frames[j].d1 = Rotate(frames[j].d1, tangents[j], a);
        frames[j].d2 = Rotate(frames[j].d2, tangents[j], a);
      }
      VecX previous(nodes);
      for (int i = 0; i < nodes; ++i) previous[i] = 20.0 * uniform(rng);
      Matrix3X x_new = x;
      for (Eigen::Index i = 0; i < x.cols(); ++i)
        x_new.col(i) += 0.2 * edge * Vec3(uniform(rng), uniform(rng), uniform(rng));
      std::vector<RefFrame> frames_ref = frames, frames_lanes = frames;
      std::vector<Vec3> tangents_ref = tangents, tangents_lanes = tangents;
      TransportFramesInTime(x_new, &tangents_ref, &frames_ref);
      const VecX twist_ref = ReferenceTwists(frames_ref, tangents_ref, previous);
      VecX twist;
      TransportFramesAndTwists(x_new, &tangents_lanes, &frames_lanes, previous, &twist, path);
      ASSERT_EQ(twist.size(), nodes);
      EXPECT_EQ(twist[0], 0.0);
      EXPECT_EQ(twist[nodes - 1], 0.0);
      for (std::size_t j = 0; j < frames.size(); ++j) {
        const double e = std::max({(frames_lanes[j].d1 - frames_ref[j].d1).norm(),
                                   (frames_lanes[j].d2 - frames_ref[j].d2).norm(),
                                   (tangents_lanes[j] - tangents_ref[j]).norm()});
        worst_frame = std::max(worst_frame, e);
        EXPECT_LT(e, 4e-15) << "nodes " << nodes << " edge " << j;
      }
      for (int i = 0; i < nodes; ++i) {
        const double e = std::abs(twist[i] - twist_ref[i]);
        worst_twist = std::max(worst_twist, e);
        EXPECT_LT(e, 4e-15 + 1e-15 * std::abs(twist_ref[i])) << "nodes " << nodes << " node " << i;
      }
      if (path == FramePath::kPortable) {  // the reference itself, bit for bit
        for (std::size_t j = 0; j < frames.size(); ++j)
          EXPECT_EQ(frames_lanes[j].d1, frames_ref[j].d1);
        EXPECT_EQ(twist, twist_ref);
      }
    }
  }
  std::printf("lanes against the portable path: frames %.2e, twists %.2e apart at most\n",
              worst_frame, worst_twist);
}

// Degenerate input fails on the lanes' paths as on the portable one, with the same message: a
// zero-length edge, and a node that is not a number (on a rod of one edge, which has no twist to
// betray it).
TEST(FramesTest, TransportFramesAndTwistsRejectsAZeroEdge) {
  HelixGeometry g;
  g.nodes = 12;
  const Matrix3X helix = HelixNodes(g);
  for (const FramePath path : {FramePath::kWidest, FramePath::kAvx2, FramePath::kPortable}) {
    Matrix3X x = helix;
    std::vector<RefFrame> frames = SpaceParallelFrames(x);
    std::vector<Vec3> tangents = EdgeTangents(x);
    x.col(6) = x.col(5);
    VecX twist;
    EXPECT_DEATH(TransportFramesAndTwists(x, &tangents, &frames, VecX(), &twist, path),
                 "zero-length edge");
    Matrix3X two = helix.leftCols(2);
    std::vector<RefFrame> frames2 = SpaceParallelFrames(two);
    std::vector<Vec3> tangents2 = EdgeTangents(two);
    two(1, 1) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_DEATH(TransportFramesAndTwists(two, &tangents2, &frames2, VecX(), &twist, path),
                 "zero-length edge");
  }
}

TEST(MaterialFrame, RotatesTheReferenceFrameByTheta) {
  const RefFrame f{Vec3::UnitX(), Vec3::UnitY()};
  Vec3 m1;
  Vec3 m2;
  MaterialFrame(f, kPi / 2, &m1, &m2);
  EXPECT_LT((m1 - Vec3::UnitY()).norm(), 1e-15);
  EXPECT_LT((m2 + Vec3::UnitX()).norm(), 1e-15);
  MaterialFrame(f, 0.7, &m1, &m2);
  EXPECT_NEAR(m1.dot(m2), 0.0, 1e-15);
  EXPECT_NEAR(SignedAngle(f.d1, m1, Vec3::UnitZ()), 0.7, 1e-15);
  EXPECT_LT((m1.cross(m2) - Vec3::UnitZ()).norm(), 1e-15);
}

}  // namespace
}  // namespace stokesrods
