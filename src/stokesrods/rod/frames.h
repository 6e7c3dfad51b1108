// Reference and material frames of a discrete rod (paper section 2.1, Fig. 2; Bergou et al. 2010).
//
// Every edge e^i = x_{i+1} − x_i carries an orthonormal reference frame {d1, d2, t} with
// t = e/|e|; the material frame {m1, m2, t} is the reference frame turned by the twist angle θ
// about t. Reference frames are built by space-parallel transport at t = 0 and carried by
// time-parallel transport at every step; the reference twist (the m_ref of paper eq. 4) measures
// how the reference frame of edge i is rotated, about t^i, relative to the space-parallel
// transport of the frame of edge i−1.
#pragma once

#include <Eigen/Geometry>  // cross products (types.h brings only Eigen/Core)
#include <vector>

#include "stokesrods/common/types.h"

namespace stokesrods {

/// Reference frame of one edge. The third director is the edge tangent t, stored apart.
struct RefFrame {
  Vec3 d1;
  Vec3 d2;
};

/// Parallel transport of u from unit tangent t0 to unit tangent t1: the rotation about t0 × t1
/// that takes t0 to t1 (identity when t0 = t1). Precondition: t0 · t1 > −1.
Vec3 ParallelTransport(const Vec3& u, const Vec3& t0, const Vec3& t1);

/// Signed angle [rad] in (−π, π] from u to v about the unit axis n (right-hand rule).
/// u and v are assumed perpendicular to n.
double SignedAngle(const Vec3& u, const Vec3& v, const Vec3& n);

/// A unit vector perpendicular to the unit vector t (deterministic choice).
Vec3 AnyPerpendicular(const Vec3& t);

/// Unit tangents of the N−1 edges of the polyline x (3 × N).
std::vector<Vec3> EdgeTangents(const Matrix3X& x);

/// Space-parallel reference frames of the N−1 edges of x: d1 of edge 0 is `first_d1` projected
/// onto the plane normal to t^0 (or AnyPerpendicular(t^0) if null), each next frame is the
/// parallel transport of the previous one from t^{i−1} to t^i. d2 = t × d1.
std::vector<RefFrame> SpaceParallelFrames(const Matrix3X& x, const Vec3* first_d1 = nullptr);

/// Time-parallel transport: frames[i] (attached to old_tangents[i]) is carried to the tangent of
/// edge i of x_new. old_tangents is updated to the new tangents.
void TransportFramesInTime(const Matrix3X& x_new, std::vector<Vec3>* old_tangents,
                           std::vector<RefFrame>* frames);

/// Reference twist [rad] at the node between edges with frames (f0, t0) and (f1, t1): the signed
/// angle about t1 from ParallelTransport(f0.d1, t0, t1) to f1.d1, shifted by a multiple of 2π to be
/// the one closest to `previous` (so the twist accumulates continuously in time).
double ReferenceTwist(const RefFrame& f0, const Vec3& t0, const RefFrame& f1, const Vec3& t1,
                      double previous);

/// Reference twists of all interior nodes 1..N−2 (entries 0 and N−1 are set to 0).
/// `previous` may be empty (treated as zeros).
VecX ReferenceTwists(const std::vector<RefFrame>& frames, const std::vector<Vec3>& tangents,
                     const VecX& previous);

/// Which instruction set transports the frames (tests run each where the CPU has it).
enum class FramePath { kWidest, kAvx2, kPortable };

/// TransportFramesInTime(x_new, tangents, frames), then twist = ReferenceTwists(*frames,
/// *tangents, previous_twist), in one pass: AVX-512 (eight edges per vector) or AVX2 with FMA
/// (four) where the CPU has them (rod/frame_lanes.h: the same formulas in another order of
/// rounding, the arctangent by glibc's vector math library), else (kPortable) by those two
/// functions, which are the reference (FramesTest.TransportFramesAndTwistsOnEachPath). Degenerate
/// input (a zero edge, opposite tangents) fails as those two functions fail.
void TransportFramesAndTwists(const Matrix3X& x_new, std::vector<Vec3>* tangents,
                              std::vector<RefFrame>* frames, const VecX& previous_twist,
                              VecX* twist, FramePath path = FramePath::kWidest);

/// Material frame of an edge: m1 = cos θ d1 + sin θ d2, m2 = −sin θ d1 + cos θ d2.
void MaterialFrame(const RefFrame& f, double theta, Vec3* m1, Vec3* m2);

}  // namespace stokesrods
