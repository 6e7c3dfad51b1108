// DetectContacts, CalcContactNormal and the displacement response (paper eqs. 17–20).
#include "stokesrods/contact/contact_response.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>

namespace stokesrods {
namespace {

std::vector<const Matrix3X*> Pointers(const std::vector<Matrix3X>& rods) {
  std::vector<const Matrix3X*> out;
  for (const Matrix3X& x : rods) out.push_back(&x);
  return out;
}

Matrix3X Nodes(std::initializer_list<Vec3> points) {
  Matrix3X x(3, static_cast<Eigen::Index>(points.size()));
  Eigen::Index i = 0;
  for (const Vec3& p : points) x.col(i++) = p;
  return x;
}

std::vector<VecX> UnitInverseMasses(const std::vector<Matrix3X>& rods) {
  std::vector<VecX> w;
  for (const Matrix3X& x : rods) w.push_back(VecX::Ones(x.cols()));
  return w;
}

double PairDistance(const std::vector<Matrix3X>& rods, const SegmentPair& p) {
  const Matrix3X& a = rods[p.a.rod];
  const Matrix3X& b = rods[p.b.rod];
  return ClosestPointsBetweenSegments(a.col(p.a.index), a.col(p.a.index + 1), b.col(p.b.index),
                                      b.col(p.b.index + 1))
      .distance;
}

void Apply(const std::vector<Matrix3X>& displacements, std::vector<Matrix3X>* rods) {
  for (std::size_t r = 0; r < rods->size(); ++r) (*rods)[r] += displacements[r];
}

/// Σ_k m_k Δx_k over all nodes with w_k > 0.
Vec3 Momentum(const std::vector<Matrix3X>& displacements, const std::vector<VecX>& w) {
  Vec3 sum = Vec3::Zero();
  for (std::size_t r = 0; r < w.size(); ++r) {
    for (Eigen::Index i = 0; i < w[r].size(); ++i) {
      if (w[r][i] > 0.0) sum += displacements[r].col(i) / w[r][i];
    }
  }
  return sum;
}

/// Change of the separation (q − p)·n of the contact points of `c` under `displacements`.
double SeparationChange(const ContactPair& c, const std::vector<Matrix3X>& d) {
  const SegmentPair& p = c.segments;
  const Vec3 dp =
      (1.0 - c.closest.s) * d[p.a.rod].col(p.a.index) + c.closest.s * d[p.a.rod].col(p.a.index + 1);
  const Vec3 dq =
      (1.0 - c.closest.t) * d[p.b.rod].col(p.b.index) + c.closest.t * d[p.b.rod].col(p.b.index + 1);
  return (dq - dp).dot(c.normal);
}

TEST(ContactResponse, CrossingAtMiddlesReachesContactDistanceExactly) {
  std::vector<Matrix3X> rods = {Nodes({{-1, 0, 0}, {1, 0, 0}}), Nodes({{0, -1, 0.1}, {0, 1, 0.1}})};
  const std::vector<ContactPair> contacts = DetectContacts(Pointers(rods), {0.1, 0.1}, 1);
  ASSERT_EQ(contacts.size(), 1u);
  const ContactPair& c = contacts[0];
  EXPECT_NEAR(c.contact_distance, 0.2, 1e-16);
  EXPECT_NEAR(c.penetration, 0.1, 1e-16);
  EXPECT_NEAR((c.normal - Vec3::UnitZ()).norm(), 0.0, 1e-16);
  const std::vector<Matrix3X> d = CalcContactDisplacements(contacts, UnitInverseMasses(rods));
  // Equal masses, s = t = ½: each node moves by ε/2, the paper's eq. 19 with |n| = ε.
  for (int r = 0; r < 2; ++r) {
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR((d[r].col(i) - (r == 0 ? -0.05 : 0.05) * Vec3::UnitZ()).norm(), 0.0, 1e-17);
    }
  }
  Apply(d, &rods);
  EXPECT_NEAR(PairDistance(rods, c.segments), 0.2, 1e-12 * 0.2);
}

TEST(ContactResponse, GeneralPositionMovesContactPointsByPenetration) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> mass(0.5, 2.0);
  // Segment b crosses a above s = 0.3, at t = 0.8 of b.
  std::vector<Matrix3X> rods = {Nodes({{-0.3, 0, 0}, {0.7, 0, 0}}),
                                Nodes({{0, -0.8, 0.17}, {0, 0.2, 0.17}})};
  const std::vector<double> radii = {0.1, 0.12};
  const double contact_distance = 0.22;
  for (int round = 0; round < 6; ++round) {
    const std::vector<ContactPair> contacts = DetectContacts(Pointers(rods), radii, 1);
    if (contacts.empty()) break;
    ASSERT_EQ(contacts.size(), 1u);
    const ContactPair& c = contacts[0];
    std::vector<VecX> w = {VecX(2), VecX(2)};
    for (VecX& v : w) v << 1.0 / mass(rng), 1.0 / mass(rng);
    const std::vector<Matrix3X> d = CalcContactDisplacements(contacts, w);
    // First order: the contact points separate by exactly ε along n; momentum is conserved.
    EXPECT_NEAR(SeparationChange(c, d), c.penetration, 1e-15);
    EXPECT_NEAR(Momentum(d, w).norm(), 0.0, 1e-16);
    for (int r = 0; r < 2; ++r) {
      for (int i = 0; i < 2; ++i) EXPECT_NEAR(d[r].col(i).cross(c.normal).norm(), 0.0, 1e-17);
    }
    Apply(d, &rods);
    const double distance = PairDistance(rods, c.segments);
    // The segments tilt, so the new distance is short of r_a + r_b by O((ε/ℓ)²) only.
    std::printf(
        "[ info ] round %d: penetration %.3g, after response |δ − (r_a + r_b)|/(r_a + r_b)"
        " = %.3g\n",
        round, c.penetration, std::abs(distance - contact_distance) / contact_distance);
    if (round == 0) {
      EXPECT_NEAR(distance, contact_distance, 1e-3 * contact_distance);
    }
  }
  EXPECT_NEAR(PairDistance(rods, {{0, 0}, {1, 0}}), contact_distance, 1e-9 * contact_distance);
}

TEST(ContactResponse, ClampedNodesNeverMove) {
  const std::vector<Matrix3X> rods = {Nodes({{-0.3, 0, 0}, {0.7, 0, 0}}),
                                      Nodes({{0, -0.8, 0.15}, {0, 0.2, 0.15}})};
  const std::vector<ContactPair> contacts = DetectContacts(Pointers(rods), {0.1, 0.1}, 1);
  ASSERT_EQ(contacts.size(), 1u);
  const ContactPair& c = contacts[0];

  std::vector<VecX> w = UnitInverseMasses(rods);
  w[0][0] = 0.0;  // clamped node a0
  std::vector<Matrix3X> d = CalcContactDisplacements(contacts, w);
  EXPECT_EQ(d[0].col(0), Vec3::Zero());
  EXPECT_NEAR(SeparationChange(c, d), c.penetration, 1e-15);

  w[0][1] = 0.0;  // the whole of segment a clamped: b takes the full displacement
  d = CalcContactDisplacements(contacts, w);
  EXPECT_EQ(d[0], Matrix3X::Zero(3, 2));
  EXPECT_NEAR(SeparationChange(c, d), c.penetration, 1e-15);
  std::vector<Matrix3X> moved = rods;
  Apply(d, &moved);
  EXPECT_GT(PairDistance(moved, c.segments), 0.2 * (1.0 - 1e-3));

  w[1].setZero();  // everything clamped: nothing moves
  d = CalcContactDisplacements(contacts, w);
  EXPECT_EQ(d[1], Matrix3X::Zero(3, 2));
}

TEST(ContactResponse, KinkVertexIsPushedOnce) {
  // The kink x1 of rod 0 points at the middle of rod 1; both segments of rod 0 have x1 as closest
  // point. Only the pair with segment 0 (s = 1) is reported; x1 moves so that the distance is
  // exactly r_a + r_b.
  std::vector<Matrix3X> rods = {Nodes({{-1, 0, -0.5}, {0, 0, 0}, {1, 0, -0.5}}),
                                Nodes({{0, -1, 0.15}, {0, 1, 0.15}})};
  const std::vector<ContactPair> contacts = DetectContacts(Pointers(rods), {0.1, 0.1}, 1);
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0].segments, (SegmentPair{{0, 0}, {1, 0}}));
  EXPECT_EQ(contacts[0].closest.s, 1.0);
  const std::vector<Matrix3X> d = CalcContactDisplacements(contacts, UnitInverseMasses(rods));
  EXPECT_NEAR(Momentum(d, UnitInverseMasses(rods)).norm(), 0.0, 1e-16);
  Apply(d, &rods);
  EXPECT_NEAR(PairDistance(rods, {{0, 0}, {1, 0}}), 0.2, 1e-12);
  EXPECT_NEAR(PairDistance(rods, {{0, 1}, {1, 0}}), 0.2, 1e-12);
}

TEST(ContactResponse, NodeSharedByTwoContactsAddsBoth) {
  // Rod 0 along x; rod 1 crosses its segment 0 and rod 2 its segment 1, both from above: node x1
  // takes part in both contacts and moves by the sum, so no penetration is left (it overshoots).
  std::vector<Matrix3X> rods = {Nodes({{-1, 0, 0}, {0, 0, 0}, {1, 0, 0}}),
                                Nodes({{-0.5, -1, 0.15}, {-0.5, 1, 0.15}}),
                                Nodes({{0.5, -1, 0.12}, {0.5, 1, 0.12}})};
  const std::vector<VecX> w = UnitInverseMasses(rods);
  const std::vector<ContactPair> contacts = DetectContacts(Pointers(rods), {0.1, 0.1, 0.1}, 1);
  ASSERT_EQ(contacts.size(), 2u);
  const std::vector<Matrix3X> d = CalcContactDisplacements(contacts, w);
  const std::vector<Matrix3X> d0 = CalcContactDisplacements({contacts[0]}, w);
  const std::vector<Matrix3X> d1 = CalcContactDisplacements({contacts[1]}, w);
  EXPECT_NEAR((d[0].col(1) - d0[0].col(1) - d1[0].col(1)).norm(), 0.0, 1e-17);
  EXPECT_GT(d0[0].col(1).norm(), 0.0);
  EXPECT_GT(d1[0].col(1).norm(), 0.0);
  EXPECT_NEAR(Momentum(d, w).norm(), 0.0, 1e-16);
  Apply(d, &rods);
  for (const ContactPair& c : contacts) {
    EXPECT_GE(PairDistance(rods, c.segments), 0.2 * (1.0 - 1e-9));
  }
}

TEST(ContactDetection, MatchesAllPairsOnRandomSoups) {
  int total = 0;
  for (unsigned seed = 0; seed < 30; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 3.0);
    std::uniform_real_distribution<double> radius(0.05, 0.3);
    std::normal_distribution<double> g(0.0, 1.0);
    std::vector<Matrix3X> rods;
    std::vector<double> radii;
    for (int r = 0; r < 4; ++r) {
      Matrix3X x(3, 15);
      x.col(0) = Vec3(u(rng), u(rng), u(rng));
      for (int i = 1; i < 15; ++i) x.col(i) = x.col(i - 1) + 0.4 * Vec3(g(rng), g(rng), g(rng));
      rods.push_back(x);
      radii.push_back(radius(rng));
    }
    const int self_exclusion = 2;
    const std::vector<ContactPair> contacts = DetectContacts(Pointers(rods), radii, self_exclusion);
    total += static_cast<int>(contacts.size());
    const auto in_contact = [&](const SegmentPair& p) {
      return PairDistance(rods, p) < radii[p.a.rod] + radii[p.b.rod];
    };
    const auto eligible = [&](const SegmentId& a, const SegmentId& b) {
      return a.rod != b.rod || std::abs(a.index - b.index) > self_exclusion;
    };
    const auto reported = [&](const SegmentPair& p) {
      for (const ContactPair& c : contacts) {
        if (c.segments == p) return true;
      }
      return false;
    };
    for (const ContactPair& c : contacts) {
      EXPECT_TRUE(in_contact(c.segments));
      EXPECT_NEAR(c.normal.norm(), 1.0, 1e-15);
      EXPECT_NEAR(c.penetration, c.contact_distance - c.closest.distance, 1e-16);
      EXPECT_NEAR(c.normal.dot(c.closest.q - c.closest.p), c.closest.distance, 1e-15);
    }
    // Every pair in contact is reported, or handed to the pair with a preceding segment.
    for (int ra = 0; ra < 4; ++ra) {
      for (int rb = ra; rb < 4; ++rb) {
        for (int i = 0; i < 14; ++i) {
          for (int j = (ra == rb ? i + 1 : 0); j < 14; ++j) {
            const SegmentPair p{{ra, i}, {rb, j}};
            if (!eligible(p.a, p.b) || !in_contact(p) || reported(p)) continue;
            const Matrix3X& a = rods[ra];
            const Matrix3X& b = rods[rb];
            const SegmentClosestPoints c =
                ClosestPointsBetweenSegments(a.col(i), a.col(i + 1), b.col(j), b.col(j + 1));
            const bool handed_a =
                c.s == 0.0 && i > 0 && eligible({ra, i - 1}, p.b) && in_contact({{ra, i - 1}, p.b});
            const bool handed_b =
                c.t == 0.0 && j > 0 && eligible(p.a, {rb, j - 1}) && in_contact({p.a, {rb, j - 1}});
            EXPECT_TRUE(handed_a || handed_b) << ra << ":" << i << " " << rb << ":" << j;
          }
        }
      }
    }
  }
  EXPECT_GT(total, 100);
}

TEST(ContactDetection, SelfContactOfHairpinSkipsNeighbours) {
  // A hairpin: 6 nodes along x at y = 0, a turn, 6 nodes back at y = 0.15 (radius 0.1: contact).
  Matrix3X x(3, 12);
  for (int i = 0; i < 6; ++i) {
    x.col(i) = Vec3(0.3 * i, 0, 0);
    x.col(11 - i) = Vec3(0.3 * i, 0.15, 0);
  }
  for (int self_exclusion : {1, 2, 4}) {
    const std::vector<ContactPair> contacts = DetectContacts({&x}, {0.1}, self_exclusion);
    EXPECT_FALSE(contacts.empty());
    for (const ContactPair& c : contacts) {
      EXPECT_GT(std::abs(c.segments.a.index - c.segments.b.index), self_exclusion);
      EXPECT_NEAR(std::abs(c.normal.y()), 1.0, 1e-15);
      EXPECT_NEAR(c.penetration, 0.05, 1e-15);
    }
  }
}

TEST(ContactNormal, FallbacksAtZeroDistance) {
  const Vec3 a0(-1, 0, 0), a1(1, 0, 0);
  // Crossing: the common perpendicular, oriented from the middle of a to the middle of b.
  {
    const Vec3 b0(0.2, -1, 0), b1(0.2, 1, 0.0);
    const auto c = ClosestPointsBetweenSegments(a0, a1, b0, b1);
    const Vec3 n = CalcContactNormal(a0, a1, b0, b1, c, 0.2);
    EXPECT_NEAR(std::abs(n.z()), 1.0, 1e-15);
    const Vec3 previous = Vec3(0, 1, -1).normalized();
    EXPECT_NEAR((CalcContactNormal(a0, a1, b0, b1, c, 0.2, &previous) - previous).norm(), 0, 1e-15);
  }
  // Collinear overlapping: perpendicular to the axis.
  {
    const Vec3 b0(0.5, 0, 0), b1(2, 0, 0);
    const auto c = ClosestPointsBetweenSegments(a0, a1, b0, b1);
    const Vec3 n = CalcContactNormal(a0, a1, b0, b1, c, 0.2);
    EXPECT_NEAR(n.norm(), 1.0, 1e-15);
    EXPECT_NEAR(n.x(), 0.0, 1e-15);
  }
  // Parallel at distance 1e-12 ≪ 1e-9 (r_a + r_b): the offset direction of the middles.
  {
    const Vec3 b0(-1, 1e-12, 0), b1(1, 1e-12, 0);
    const auto c = ClosestPointsBetweenSegments(a0, a1, b0, b1);
    EXPECT_NEAR((CalcContactNormal(a0, a1, b0, b1, c, 0.2) - Vec3::UnitY()).norm(), 0.0, 1e-15);
  }
  // Two coincident points: a fixed unit vector.
  {
    const Vec3 p(1, 2, 3);
    const auto c = ClosestPointsBetweenSegments(p, p, p, p);
    EXPECT_EQ(CalcContactNormal(p, p, p, p, c, 0.2), Vec3::UnitX());
  }
  // Through DetectContacts: the previous contact's normal is kept at distance 0.
  {
    std::vector<Matrix3X> rods = {Nodes({a0, a1}), Nodes({{0.2, -1, 0}, {0.2, 1, 0}})};
    std::vector<ContactPair> previous = DetectContacts(Pointers(rods), {0.1, 0.1}, 1);
    ASSERT_EQ(previous.size(), 1u);
    previous[0].normal = Vec3(0, 0, -1);
    const auto contacts = DetectContacts(Pointers(rods), {0.1, 0.1}, 1, &previous);
    ASSERT_EQ(contacts.size(), 1u);
    EXPECT_EQ(contacts[0].normal, Vec3(0, 0, -1));
  }
}

// DetectContacts with the broad phase kept across calls (CandidatePairList) finds the same
// contacts, bit for bit, as with a new search at each call, on two crossing rods that slide
// through and past each other in small steps (contacts found, lost and found again).
TEST(DetectContacts, KeptCandidateListFindsTheSameContacts) {
  CandidatePairList list;
  int with_contacts = 0;
  for (int call = 0; call <= 400; ++call) {
    const double z = -0.3 + 0.0015 * call;  // the second rod passes through the first
    std::vector<Matrix3X> rods = {Nodes({{-1, 0, 0}, {-0.5, 0.02, 0}, {0, 0, 0}, {0.5, -0.02, 0}, {1, 0, 0}}),
                                  Nodes({{0.1, -1, z}, {0.12, -0.4, z}, {0.1, 0.2, z}, {0.08, 1, z}})};
    const auto fresh = DetectContacts(Pointers(rods), {0.1, 0.1}, 1);
    const auto kept = DetectContacts(Pointers(rods), {0.1, 0.1}, 1, nullptr, &list);
    ASSERT_EQ(fresh.size(), kept.size()) << "call " << call;
    for (std::size_t k = 0; k < fresh.size(); ++k) {
      EXPECT_EQ(fresh[k].segments, kept[k].segments);
      EXPECT_EQ(fresh[k].penetration, kept[k].penetration);
      EXPECT_EQ(fresh[k].normal, kept[k].normal);
    }
    with_contacts += fresh.empty() ? 0 : 1;
  }
  EXPECT_GT(with_contacts, 50);
  EXPECT_LT(with_contacts, 350);
  EXPECT_LT(list.searches(), 100);  // 0.0015 per call against a skin's half of 0.05
}

}  // namespace
}  // namespace stokesrods
