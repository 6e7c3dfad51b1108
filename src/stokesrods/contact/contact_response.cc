// Contact detection and displacement response (paper section 2.3); formulas in the header.
#include "stokesrods/contact/contact_response.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "stokesrods/common/assert.h"

namespace stokesrods {
namespace {

constexpr double kMachineEps = std::numeric_limits<double>::epsilon();
/// Below this fraction of r_a + r_b, q − p is too short to give a direction.
constexpr double kNormalFallbackRatio = 1e-9;
/// sin² of the angle under which two segments count as parallel for the normal (angle 1e-6).
constexpr double kParallelSinSq = 1e-12;

/// A fixed unit vector perpendicular to u ≠ 0: u × (the axis along u's smallest component).
Vec3 AnyPerpendicular(const Vec3& u) {
  Eigen::Index k = 0;
  u.cwiseAbs().minCoeff(&k);
  return u.cross(Vec3::Unit(k)).normalized();
}

/// Flips v so that it points along `towards`, or, when v ⟂ towards, so that its largest component
/// is positive: a deterministic orientation.
Vec3 Orient(const Vec3& v, const Vec3& towards) {
  const double along = v.dot(towards);
  if (std::abs(along) > 1e-12 * towards.norm()) return along > 0.0 ? v : Vec3(-v);
  Eigen::Index k = 0;
  v.cwiseAbs().maxCoeff(&k);
  return v[k] >= 0.0 ? v : Vec3(-v);
}

const ContactPair* FindPrevious(const std::vector<ContactPair>* previous, const SegmentPair& pair) {
  if (previous == nullptr) return nullptr;
  const auto key = [](const SegmentPair& p) {
    return std::array<int, 4>{p.a.rod, p.a.index, p.b.rod, p.b.index};
  };
  const auto it = std::lower_bound(
      previous->begin(), previous->end(), key(pair),
      [&key](const ContactPair& c, const std::array<int, 4>& k) { return key(c.segments) < k; });
  return (it != previous->end() && it->segments == pair) ? &*it : nullptr;
}

bool Eligible(const SegmentId& a, const SegmentId& b, int self_exclusion) {
  return a.rod != b.rod || std::abs(a.index - b.index) > self_exclusion;
}

/// True when the contact at the first node of a (s = 0) or of b (t = 0) is also a contact of the
/// eligible pair with the preceding segment, which then reports it (see DetectContacts).
bool HandedToPrecedingSegment(const SegmentPair& pair, const SegmentClosestPoints& c,
                              int self_exclusion) {
  if (c.s == 0.0 && pair.a.index > 0) {
    const SegmentId before{pair.a.rod, pair.a.index - 1};
    if (Eligible(before, pair.b, self_exclusion)) return true;
  }
  if (c.t == 0.0 && pair.b.index > 0) {
    const SegmentId before{pair.b.rod, pair.b.index - 1};
    if (Eligible(pair.a, before, self_exclusion)) return true;
  }
  return false;
}

}  // namespace

Vec3 CalcContactNormal(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1,
                       const SegmentClosestPoints& closest, double contact_distance,
                       const Vec3* previous_normal) {
  const Vec3 pq = closest.q - closest.p;
  const double coordinate_roundoff = 64.0 * kMachineEps *
                                     std::max({a0.cwiseAbs().maxCoeff(), a1.cwiseAbs().maxCoeff(),
                                               b0.cwiseAbs().maxCoeff(), b1.cwiseAbs().maxCoeff()});
  const double too_short = kNormalFallbackRatio * contact_distance + coordinate_roundoff;
  const double length = pq.norm();
  if (length > too_short) return pq / length;

  if (previous_normal != nullptr && previous_normal->allFinite() && previous_normal->norm() > 0.0) {
    return previous_normal->normalized();
  }
  const Vec3 da = a1 - a0;
  const Vec3 db = b1 - b0;
  const Vec3 mid_ab = 0.5 * (b0 + b1) - 0.5 * (a0 + a1);
  const Vec3 cross = da.cross(db);
  if (cross.squaredNorm() > kParallelSinSq * da.squaredNorm() * db.squaredNorm()) {
    return Orient(cross.normalized(), mid_ab);
  }
  // Parallel, or at least one segment of zero length: use the longer one's direction.
  const Vec3 axis = da.squaredNorm() >= db.squaredNorm() ? da : db;
  // The offset of the middles is trusted down to the round-off of the coordinates.
  if (!(axis.squaredNorm() > 0.0)) {
    return mid_ab.norm() > coordinate_roundoff ? Vec3(mid_ab.normalized()) : Vec3(Vec3::UnitX());
  }
  const Vec3 u = axis.normalized();
  const Vec3 across = mid_ab - mid_ab.dot(u) * u;
  if (across.norm() > coordinate_roundoff) return across.normalized();
  return AnyPerpendicular(u);
}

std::vector<ContactPair> DetectContacts(const std::vector<const Matrix3X*>& rods,
                                        const std::vector<double>& radii, int self_exclusion,
                                        const std::vector<ContactPair>* previous,
                                        CandidatePairList* candidate_list) {
  SR_ASSERT(rods.size() == radii.size(), "one radius per rod");
  SR_ASSERT(self_exclusion >= 0, "self_exclusion must be >= 0");
  double max_radius = 0.0;
  for (double r : radii) {
    SR_ASSERT(r >= 0.0 && std::isfinite(r), "radii must be finite and >= 0");
    max_radius = std::max(max_radius, r);
  }
  // δ_min < r_a + r_b ≤ 2 max r implies boxes inflated by max r each overlap.
  std::vector<SegmentPair> found;
  if (!candidate_list) found = FindCandidatePairs(rods, max_radius, self_exclusion);
  const std::vector<SegmentPair>& candidates =
      candidate_list ? candidate_list->Pairs(rods, max_radius, self_exclusion) : found;

  std::vector<ContactPair> contacts;
  for (const SegmentPair& pair : candidates) {
    const Matrix3X& xa = *rods[pair.a.rod];
    const Matrix3X& xb = *rods[pair.b.rod];
    const Vec3 a0 = xa.col(pair.a.index);
    const Vec3 a1 = xa.col(pair.a.index + 1);
    const Vec3 b0 = xb.col(pair.b.index);
    const Vec3 b1 = xb.col(pair.b.index + 1);
    const SegmentClosestPoints closest = ClosestPointsBetweenSegments(a0, a1, b0, b1);
    const double contact_distance = radii[pair.a.rod] + radii[pair.b.rod];
    if (!(closest.distance < contact_distance)) continue;
    if (HandedToPrecedingSegment(pair, closest, self_exclusion)) continue;

    ContactPair contact;
    contact.segments = pair;
    contact.closest = closest;
    contact.contact_distance = contact_distance;
    contact.penetration = contact_distance - closest.distance;
    const ContactPair* before = FindPrevious(previous, pair);
    contact.normal = CalcContactNormal(a0, a1, b0, b1, closest, contact_distance,
                                       before != nullptr ? &before->normal : nullptr);
    contacts.push_back(contact);
  }
  return contacts;
}

void AddContactDisplacements(const ContactPair& contact, const std::vector<VecX>& inverse_masses,
                             std::vector<Matrix3X>* displacements) {
  SR_ASSERT(displacements != nullptr, "displacements must not be null");
  SR_ASSERT(displacements->size() == inverse_masses.size(), "one inverse-mass vector per rod");
  struct NodeTerm {
    int rod;
    Eigen::Index node;
    double coefficient;  // c_k: ∂(q − p)·n / ∂x_k · n
  };
  const SegmentPair& pair = contact.segments;
  const double s = contact.closest.s;
  const double t = contact.closest.t;
  std::array<NodeTerm, 4> terms = {
      NodeTerm{pair.a.rod, pair.a.index, -(1.0 - s)}, NodeTerm{pair.a.rod, pair.a.index + 1, -s},
      NodeTerm{pair.b.rod, pair.b.index, 1.0 - t}, NodeTerm{pair.b.rod, pair.b.index + 1, t}};
  // Segments of one rod may share a node (self_exclusion = 0): merge its coefficients.
  for (std::size_t k = 0; k < terms.size(); ++k) {
    for (std::size_t l = k + 1; l < terms.size(); ++l) {
      if (terms[l].rod == terms[k].rod && terms[l].node == terms[k].node) {
        terms[k].coefficient += terms[l].coefficient;
        terms[l].coefficient = 0.0;
      }
    }
  }
  double weight_sum = 0.0;  // W = Σ w_k c_k²  [1/kg]
  std::array<double, 4> w{};
  for (std::size_t k = 0; k < terms.size(); ++k) {
    const VecX& inverse_mass = inverse_masses[terms[k].rod];
    SR_ASSERT(terms[k].node < inverse_mass.size() &&
                  terms[k].node < (*displacements)[terms[k].rod].cols(),
              "node index beyond the rod's inverse masses or displacements");
    w[k] = inverse_mass[terms[k].node];
    SR_ASSERT(w[k] >= 0.0, "inverse masses must be >= 0 (0 for a clamped node)");
    weight_sum += w[k] * terms[k].coefficient * terms[k].coefficient;
  }
  if (!(weight_sum > 0.0)) return;                         // every node that could move is clamped
  const double lambda = contact.penetration / weight_sum;  // [m kg]
  for (std::size_t k = 0; k < terms.size(); ++k) {
    (*displacements)[terms[k].rod].col(terms[k].node) +=
        (lambda * w[k] * terms[k].coefficient) * contact.normal;
  }
}

std::vector<Matrix3X> CalcContactDisplacements(const std::vector<ContactPair>& contacts,
                                               const std::vector<VecX>& inverse_masses) {
  std::vector<Matrix3X> displacements;
  displacements.reserve(inverse_masses.size());
  for (const VecX& w : inverse_masses) displacements.push_back(Matrix3X::Zero(3, w.size()));
  for (const ContactPair& contact : contacts) {
    AddContactDisplacements(contact, inverse_masses, &displacements);
  }
  return displacements;
}

}  // namespace stokesrods
