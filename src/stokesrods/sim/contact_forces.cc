#include "stokesrods/sim/contact_forces.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "stokesrods/contact/contact_response.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {

int SelfContactExclusion(const RodModel& rod) {
  // Two segments of one rod that are fewer than this many edges apart cannot reach each other
  // without folding the rod tighter than its own diameter; adjacent ones always touch.
  const double shortest = rod.rest_edge_length.minCoeff();
  return static_cast<int>(std::ceil(2.0 * rod.radius / shortest)) + 1;
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
  for (std::size_t a = 0; a < in.positions.size(); ++a)
    for (std::size_t b = a + 1; b < in.positions.size(); ++b) {
      const Matrix3X& xa = in.positions[a];
      const Matrix3X& xb = in.positions[b];
      for (Eigen::Index i = 0; i + 1 < xa.cols(); ++i)
        for (Eigen::Index j = 0; j + 1 < xb.cols(); ++j)
          best = std::min(best, ClosestPointsBetweenSegments(xa.col(i), xa.col(i + 1), xb.col(j),
                                                             xb.col(j + 1)).distance);
    }
  return best;
}

ContactSummary AddContactForces(const Model& model, const VecX& q, double h,
                                VecX* contact_force) {
  const ContactInput in = MakeInput(model, q);
  const std::vector<ContactPair> pairs = DetectContacts(in.rods, in.radii, in.self_exclusion);
  const ContactSummary summary = Summarize(model, pairs);
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
  const std::vector<Matrix3X> dx = CalcContactDisplacements(pairs, inverse_masses);
  for (std::size_t r = 0; r < model.rods.size(); ++r) {  // eq. 20: F = m Δx / h²
    const RodModel& rod = model.rods[r];
    for (int i = 0; i < rod.num_nodes(); ++i)
      contact_force->segment<3>(rod.dof_offset + NodeDof(i)) +=
          rod.mass(NodeDof(i)) * dx[r].col(i) / (h * h);
  }
  return summary;
}

}  // namespace stokesrods
