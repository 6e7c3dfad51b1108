#include "stokesrods/sim/contact_forces.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "stokesrods/contact/contact_response.h"
#include "stokesrods/sim/body_contact.h"
#include "stokesrods/sim/obstacle_contact.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {

std::string DescribeDeepest(const ContactSummary& summary) {
  auto segment = [](const SegmentId& s) {
    return fmt::format("rod {}, segment {} (nodes {}-{})", s.rod + 1, s.index, s.index,
                       s.index + 1);
  };
  auto obstacle = [&] {
    return summary.obstacle_body < 0 ? std::string("the wall")
                                     : fmt::format("body {}", summary.obstacle_body + 1);
  };
  if (summary.deepest_body >= 0)
    return fmt::format("body {} against {}", summary.deepest_body + 1, obstacle());
  if (summary.obstacle_node >= 0)
    return fmt::format("rod {}, node {} against {}", summary.deepest.a.rod + 1,
                       summary.obstacle_node, obstacle());
  return segment(summary.deepest.a) + " against " + segment(summary.deepest.b);
}

int SelfContactExclusion(const RodModel& rod) {
  // Two segments of one rod that are fewer than this many edges apart cannot reach each other
  // without folding the rod tighter than its own diameter; adjacent ones always touch. At most
  // the rod's edge count (then no pair of its own is tested): a radius far beyond the edges (the
  // fuzzer's 1e7 m on 5 mm edges) would overflow an int.
  const auto edges = static_cast<double>(rod.rest_edge_length.size());
  const double shortest = rod.rest_edge_length.minCoeff();
  return static_cast<int>(std::min(std::ceil(2.0 * rod.radius / shortest) + 1.0, std::max(edges, 1.0)));
}

namespace {

struct ContactInput {
  std::vector<Matrix3X> positions;
  std::vector<const Matrix3X*> rods;
  std::vector<double> radii;
  int self_exclusion = 1;
};

ContactInput MakeInput(const Model& model, const VecX& q) {
  ContactInput in;
  for (int r = 0; r < static_cast<int>(model.rods.size()); ++r) {
    in.positions.push_back(RodPositions(model, r, q));
    in.radii.push_back(model.rods[r].radius);
    in.self_exclusion = std::max(in.self_exclusion, SelfContactExclusion(model.rods[r]));
  }
  for (const Matrix3X& x : in.positions) in.rods.push_back(&x);
  return in;
}

ContactSummary Summarize(const Model& model, const std::vector<ContactPair>& pairs) {
  ContactSummary summary;
  summary.detected = static_cast<int>(pairs.size());
  for (const ContactPair& pair : pairs) {
    if (pair.penetration >= summary.max_penetration)
      summary.deepest = pair.segments, summary.deepest_contact_distance = pair.contact_distance;
    summary.max_penetration = std::max(summary.max_penetration, pair.penetration);
    if (pair.penetration > model.newton.contact_tolerance * pair.contact_distance) ++summary.active;
  }
  return summary;
}

}  // namespace

ContactSummary MeasureContacts(const Model& model, const VecX& q) {
  const ContactInput in = MakeInput(model, q);
  return Summarize(model, DetectContacts(in.rods, in.radii, in.self_exclusion));
}

double MinDistanceBetweenRods(const Model& model, const VecX& q) {
  double best = std::numeric_limits<double>::infinity();
  const ContactInput in = MakeInput(model, q);
  // Rod pairs whose bounding boxes are farther apart than the best distance so far cannot hold
  // the minimum (O(R²) box tests instead of O(R² N²) segment pairs for many rods).
  std::vector<Eigen::AlignedBox3d> boxes(in.positions.size());
  for (std::size_t a = 0; a < in.positions.size(); ++a)
    for (Eigen::Index i = 0; i < in.positions[a].cols(); ++i) boxes[a].extend(Vec3(in.positions[a].col(i)));
  for (std::size_t a = 0; a < in.positions.size(); ++a)
    for (std::size_t b = a + 1; b < in.positions.size(); ++b) {
      if (boxes[a].exteriorDistance(boxes[b]) >= best) continue;
      const Matrix3X& xa = in.positions[a];
      const Matrix3X& xb = in.positions[b];
      for (Eigen::Index i = 0; i + 1 < xa.cols(); ++i)
        for (Eigen::Index j = 0; j + 1 < xb.cols(); ++j)
          best = std::min(best, ClosestPointsBetweenSegments(xa.col(i), xa.col(i + 1), xb.col(j),
                                                             xb.col(j + 1)).distance);
    }
  return best;
}

namespace {

// Change of the separation of `pair` along its normal under the nodal displacement dq.
double SeparationChange(const Model& model, const ContactPair& pair, const VecX& dq) {
  auto node = [&](const SegmentId& seg, int k) {
    return Vec3(dq.segment<3>(model.rods[seg.rod].dof_offset + NodeDof(seg.index + k)));
  };
  const double s = pair.closest.s, t = pair.closest.t;
  const Vec3 moved_a = (1.0 - s) * node(pair.segments.a, 0) + s * node(pair.segments.a, 1);
  const Vec3 moved_b = (1.0 - t) * node(pair.segments.b, 0) + t * node(pair.segments.b, 1);
  return pair.normal.dot(moved_b - moved_a);
}

// λ ≥ 0 with W λ = ε on the pairs that stay active (a pair with λ < 0 is pulled, not pushed:
// dropped and the rest solved again).
VecX SolveMultipliers(const MatX& w, const VecX& eps) {
  const Eigen::Index p = eps.size();
  std::vector<bool> active(p, true);
  VecX lambda = VecX::Zero(p);
  for (int pass = 0; pass < p + 1; ++pass) {
    std::vector<Eigen::Index> idx;
    for (Eigen::Index k = 0; k < p; ++k) if (active[k]) idx.push_back(k);
    if (idx.empty()) break;
    MatX ws(idx.size(), idx.size());
    VecX rhs(idx.size());
    for (std::size_t a = 0; a < idx.size(); ++a) {
      rhs(a) = eps(idx[a]);
      for (std::size_t b = 0; b < idx.size(); ++b) ws(a, b) = w(idx[a], idx[b]);
    }
    const VecX sub = ws.fullPivLu().solve(rhs);
    lambda.setZero();
    bool negative = false;
    for (std::size_t a = 0; a < idx.size(); ++a) {
      lambda(idx[a]) = sub(a);
      if (!(sub(a) >= 0.0)) active[idx[a]] = false, negative = true;
    }
    if (!negative) return lambda;
  }
  // No consistent solution: fall back to each pair on its own.
  for (Eigen::Index k = 0; k < p; ++k) lambda(k) = w(k, k) > 0.0 ? eps(k) / w(k, k) : 1.0;
  return lambda;
}

}  // namespace

namespace {

// The obstacles' and the bodies' pairs into the summary (the rods' are in already).
void SummarizeOthers(const Model& model, const std::vector<ObstaclePair>& obstacles,
                     const std::vector<BodyPair>& bodies, ContactSummary* summary) {
  auto count = [&](double penetration, double contact_distance) {
    ++summary->detected;
    const bool deepest = penetration >= summary->max_penetration;
    summary->max_penetration = std::max(summary->max_penetration, penetration);
    if (penetration > model.newton.contact_tolerance * contact_distance) ++summary->active;
    if (deepest) summary->deepest_contact_distance = contact_distance;
    return deepest;
  };
  for (const ObstaclePair& o : obstacles)
    if (count(o.penetration, model.rods[o.rod].radius)) {
      summary->deepest = SegmentPair{{o.rod, o.node}, {o.rod, o.node}};
      summary->obstacle_node = o.node;
      summary->obstacle_body = o.body;
      summary->deepest_body = -1;
    }
  for (const BodyPair& b : bodies)
    if (count(b.penetration, b.contact_distance)) {
      summary->deepest_body = b.body;
      summary->obstacle_body = b.other;
      summary->obstacle_node = -1;
    }
}

}  // namespace

ContactSummary AddContactForces(const Model& model, const VecX& q, double h,
                                const LinearResponse& respond, VecX* contact_force,
                                const std::vector<BodyPose>& poses, VecX* body_loads,
                                CandidatePairList* candidates) {
  const ContactInput in = MakeInput(model, q);
  const std::vector<ContactPair> pairs =
      DetectContacts(in.rods, in.radii, in.self_exclusion, nullptr, candidates);
  ContactSummary summary = Summarize(model, pairs);
  const bool have_poses = poses.size() == model.bodies.size();
  const std::vector<ObstaclePair> obstacles =
      have_poses ? DetectObstacleContacts(model, q, poses) : std::vector<ObstaclePair>();
  const std::vector<BodyPair> bodies =
      have_poses ? DetectBodyContacts(model, poses) : std::vector<BodyPair>();
  SummarizeOthers(model, obstacles, bodies, &summary);
  if (summary.active == 0) return summary;

  // Clamped nodes have zero inverse mass: they never move, the other side takes it all.
  std::vector<VecX> inverse_masses;
  for (const RodModel& rod : model.rods) {
    VecX w(rod.num_nodes());
    for (int i = 0; i < rod.num_nodes(); ++i) {
      const bool fixed = std::binary_search(rod.fixed_dofs.begin(), rod.fixed_dofs.end(),
                                            NodeDof(i));
      w(i) = fixed ? 0.0 : 1.0 / rod.mass(NodeDof(i));
    }
    inverse_masses.push_back(std::move(w));
  }
  // Per pair: its trial force F_k on the rods (eq. 19–20) and loads L_k on the free bodies, and
  // the response of every pair's separation to them. The rods' pairs first, then the obstacles'
  // (obstacle_contact.h: the node moves, and a free body with its reaction), then the bodies'.
  const auto pr = static_cast<Eigen::Index>(pairs.size());
  const auto po = pr + static_cast<Eigen::Index>(obstacles.size());
  const Eigen::Index p = po + static_cast<Eigen::Index>(bodies.size());
  const int loads_size = 6 * model.num_free_bodies;
  std::vector<VecX> forces(static_cast<std::size_t>(p), VecX::Zero(model.num_dofs));
  std::vector<VecX> loads(static_cast<std::size_t>(p), VecX::Zero(loads_size));
  auto obstacle = [&](Eigen::Index k) -> const ObstaclePair& { return obstacles[static_cast<std::size_t>(k - pr)]; };
  auto body_pair = [&](Eigen::Index k) -> const BodyPair& { return bodies[static_cast<std::size_t>(k - po)]; };
  auto node_dof = [&](const ObstaclePair& o) { return model.rods[o.rod].dof_offset + NodeDof(o.node); };
  MatX w(p, p);
  VecX eps(p), dq, dv = VecX::Zero(loads_size);
  for (Eigen::Index k = 0; k < p; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    if (k < pr) {
      const std::vector<Matrix3X> dx = CalcContactDisplacements({pairs[kk]}, inverse_masses);
      for (std::size_t r = 0; r < model.rods.size(); ++r) {
        const RodModel& rod = model.rods[r];
        for (int i = 0; i < rod.num_nodes(); ++i)
          forces[kk].segment<3>(rod.dof_offset + NodeDof(i)) =
              rod.mass(NodeDof(i)) * dx[r].col(i) / (h * h);
      }
      eps(k) = pairs[kk].penetration;
    } else if (k < po) {
      const ObstaclePair& o = obstacle(k);
      const Vec3 f = model.rods[o.rod].mass(NodeDof(o.node)) * o.penetration * o.normal / (h * h);
      forces[kk].segment<3>(node_dof(o)) = f;
      AddObstacleReaction(model, o, f, poses, &loads[kk]);
      eps(k) = o.penetration;
    } else {
      const BodyPair& b = body_pair(k);
      AddBodyPairLoads(model, b, BodyPairTrialForce(model, b, h), poses, &loads[kk]);
      eps(k) = b.penetration;
    }
    respond(forces[kk], loads[kk], &dq, &dv);
    for (Eigen::Index j = 0; j < p; ++j) {
      if (j < pr) {
        w(j, k) = SeparationChange(model, pairs[static_cast<std::size_t>(j)], dq);
      } else if (j < po) {
        const ObstaclePair& o = obstacle(j);
        w(j, k) = o.normal.dot(dq.segment<3>(node_dof(o)) -
                               BodyPointShift(model, o.body, poses, o.point, h, dv));
      } else {
        w(j, k) = BodyPairSeparationChange(model, body_pair(j), poses, h, dv);
      }
    }
  }
  const VecX lambda = SolveMultipliers(w, eps);
  for (Eigen::Index k = 0; k < p; ++k) {
    *contact_force += lambda(k) * forces[static_cast<std::size_t>(k)];
    if (body_loads && loads_size > 0) *body_loads += lambda(k) * loads[static_cast<std::size_t>(k)];
  }
  return summary;
}

}  // namespace stokesrods
