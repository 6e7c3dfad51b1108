// FindCandidatePairs (uniform grid) against the brute force, and its cost on a sparse soup.
#include "stokesrods/contact/broad_phase.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

namespace stokesrods {
namespace {

/// `count` random-walk polylines with `nodes` nodes each, steps of length in [0.5, 1.5], starting
/// uniformly in a cube of side `box`.
std::vector<Matrix3X> RandomSoup(std::mt19937* rng, int count, int nodes, double box) {
  std::uniform_real_distribution<double> start(0.0, box);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> step(0.5, 1.5);
  std::vector<Matrix3X> rods;
  for (int r = 0; r < count; ++r) {
    Matrix3X x(3, nodes);
    x.col(0) = Vec3(start(*rng), start(*rng), start(*rng));
    for (int i = 1; i < nodes; ++i) {
      const Vec3 dir = Vec3(gauss(*rng), gauss(*rng), gauss(*rng)).normalized();
      x.col(i) = x.col(i - 1) + step(*rng) * dir;
    }
    rods.push_back(x);
  }
  return rods;
}

std::vector<const Matrix3X*> Pointers(const std::vector<Matrix3X>& rods) {
  std::vector<const Matrix3X*> out;
  for (const Matrix3X& x : rods) out.push_back(&x);
  return out;
}

bool Sorted(const std::vector<SegmentPair>& pairs) {
  const auto key = [](const SegmentPair& p) {
    return std::array<int, 4>{p.a.rod, p.a.index, p.b.rod, p.b.index};
  };
  for (std::size_t k = 1; k < pairs.size(); ++k) {
    if (!(key(pairs[k - 1]) < key(pairs[k]))) return false;  // strictly: sorted and unique
  }
  for (const SegmentPair& p : pairs) {
    if (!(std::array<int, 2>{p.a.rod, p.a.index} < std::array<int, 2>{p.b.rod, p.b.index})) {
      return false;
    }
  }
  return true;
}

// Every pair of `exact` is in `kept` (both sorted as FindCandidatePairs sorts).
bool Holds(const std::vector<SegmentPair>& kept, const std::vector<SegmentPair>& exact) {
  const auto key = [](const SegmentPair& p) {
    return std::array<int, 4>{p.a.rod, p.a.index, p.b.rod, p.b.index};
  };
  return std::includes(kept.begin(), kept.end(), exact.begin(), exact.end(),
                       [&](const SegmentPair& p, const SegmentPair& q) { return key(p) < key(q); });
}

TEST(BroadPhase, EqualsBruteForceOnRandomSoups) {
  std::size_t total_pairs = 0;
  for (unsigned seed = 0; seed < 60; ++seed) {
    std::mt19937 rng(seed);
    const int count = 2 + static_cast<int>(seed % 7);
    const int nodes = 2 + static_cast<int>((seed * 13) % 40);
    const std::vector<Matrix3X> rods = RandomSoup(&rng, count, nodes, 6.0);
    for (double margin : {0.0, 0.05, 0.3, 1.0, 3.0}) {
      for (int self_exclusion : {0, 1, 2, 5}) {
        SCOPED_TRACE(testing::Message() << "seed " << seed << " margin " << margin
                                        << " self_exclusion " << self_exclusion);
        const auto grid = FindCandidatePairs(Pointers(rods), margin, self_exclusion);
        const auto brute = FindCandidatePairsBruteForce(Pointers(rods), margin, self_exclusion);
        ASSERT_EQ(grid, brute);
        EXPECT_TRUE(Sorted(grid));
        for (const SegmentPair& p : grid) {
          EXPECT_FALSE(p.a.rod == p.b.rod && std::abs(p.a.index - p.b.index) <= self_exclusion);
        }
        total_pairs += grid.size();
      }
    }
  }
  EXPECT_GT(total_pairs, 10000u);  // the comparison is not vacuous
}

// A soup spread over 1e9 times its segments' size: more than 2^20 cells of the segments' extent
// per axis, so the grid takes larger cells (a cell's key is one 64-bit integer); still every pair
// the brute force finds, and no other.
TEST(BroadPhase, ExtentFarBeyondTheSegmentsEqualsBruteForce) {
  std::mt19937 rng(11);
  std::vector<Matrix3X> rods = RandomSoup(&rng, 4, 30, 3.0);
  rods[3].colwise() += Vec3(1e9, -2e9, 5e8);  // one rod far away, the others among themselves
  EXPECT_EQ(FindCandidatePairs(Pointers(rods), 0.2, 1),
            FindCandidatePairsBruteForce(Pointers(rods), 0.2, 1));
  EXPECT_FALSE(FindCandidatePairs(Pointers(rods), 0.2, 1).empty());
}

TEST(BroadPhase, DegenerateInputs) {
  // No rods, one-node rods, all nodes at one point, a non-finite node.
  EXPECT_TRUE(FindCandidatePairs({}, 0.1, 1).empty());
  const Matrix3X single = Matrix3X::Zero(3, 1);
  EXPECT_TRUE(FindCandidatePairs({&single, &single}, 0.1, 1).empty());
  const Matrix3X point = Matrix3X::Ones(3, 5);
  for (double margin : {0.0, 1.0}) {
    EXPECT_EQ(FindCandidatePairs({&point, &point}, margin, 1),
              FindCandidatePairsBruteForce({&point, &point}, margin, 1));
    EXPECT_EQ(FindCandidatePairs({&point, &point}, margin, 1).size(), 16u + 2u * 3u);
  }
  std::mt19937 rng(5);
  std::vector<Matrix3X> rods = RandomSoup(&rng, 3, 20, 3.0);
  rods[1](1, 7) = std::numeric_limits<double>::quiet_NaN();
  const auto grid = FindCandidatePairs(Pointers(rods), 0.2, 1);
  EXPECT_EQ(grid, FindCandidatePairsBruteForce(Pointers(rods), 0.2, 1));
  for (const SegmentPair& p : grid) {
    for (const SegmentId& s : {p.a, p.b}) {
      EXPECT_FALSE(s.rod == 1 && (s.index == 6 || s.index == 7));
    }
  }
}

TEST(BroadPhase, FarFewerTestsThanBruteForceOnSparseSoup) {
  // 400 rods of 50 segments in a cube of side 60: n = 20000 segments, brute force n(n−1)/2 ≈ 2e8.
  std::mt19937 rng(42);
  const std::vector<Matrix3X> rods = RandomSoup(&rng, 400, 51, 60.0);
  BroadPhaseStats stats;
  const auto grid = FindCandidatePairs(Pointers(rods), 0.1, 2, &stats);
  const double n = static_cast<double>(stats.segments);
  const double brute_tests = 0.5 * n * (n - 1.0);
  std::printf(
      "[ info ] %lld segments: %lld box tests, %lld cell-pair visits, brute force %.3g "
      "tests; %lld cell entries, %zu pairs\n",
      static_cast<long long>(stats.segments), static_cast<long long>(stats.box_tests),
      static_cast<long long>(stats.cell_pairs), brute_tests,
      static_cast<long long>(stats.cell_entries), grid.size());
  EXPECT_EQ(stats.segments, 20000);
  EXPECT_LT(static_cast<double>(stats.box_tests), 1e-3 * brute_tests);
  EXPECT_LT(stats.box_tests, 40 * stats.segments);  // about linear in n
  EXPECT_LT(stats.cell_pairs, 40 * stats.segments);
  EXPECT_LE(stats.cell_entries, 8 * stats.segments);

  // Doubling the soup at the same density about doubles the work.
  std::mt19937 rng2(43);
  const std::vector<Matrix3X> twice = RandomSoup(&rng2, 800, 51, 60.0 * std::cbrt(2.0));
  BroadPhaseStats stats2;
  FindCandidatePairs(Pointers(twice), 0.1, 2, &stats2);
  const double ratio = static_cast<double>(stats2.box_tests) / static_cast<double>(stats.box_tests);
  std::printf("[ info ] doubling n at constant density: box tests x %.2f\n", ratio);
  EXPECT_LT(ratio, 3.0);
}

TEST(BroadPhase, MediumSoupEqualsBruteForce) {
  std::mt19937 rng(99);
  const std::vector<Matrix3X> rods = RandomSoup(&rng, 60, 41, 20.0);
  EXPECT_EQ(FindCandidatePairs(Pointers(rods), 0.25, 3),
            FindCandidatePairsBruteForce(Pointers(rods), 0.25, 3));
}

// The list kept across calls (a Verlet list) against a new search at every call: the rods of a
// soup drift by small random steps (each coordinate by up to a tenth of the margin per call, so
// that the list is found again every few calls), and at every call the list must hold every pair
// of FindCandidatePairs, sorted. A list kept past the skin's half (the validity test off by a
// factor 4) loses pairs here: 0.5 s → 2 s misses some of them within the 200 calls.
TEST(CandidatePairList, HoldsEveryPairOfANewSearchAsTheRodsMove) {
  std::mt19937 rng(11);
  std::vector<Matrix3X> rods = RandomSoup(&rng, 12, 20, 12.0);
  std::uniform_real_distribution<double> drift(-1.0, 1.0);
  const double margin = 0.3;
  CandidatePairList list;
  int calls = 0;
  std::size_t most_pairs = 0;
  for (int call = 0; call < 200; ++call, ++calls) {
    for (Matrix3X& x : rods)
      for (Eigen::Index i = 0; i < x.cols(); ++i)
        x.col(i) += 0.1 * margin * Vec3(drift(rng), drift(rng), drift(rng));
    const std::vector<SegmentPair> exact = FindCandidatePairs(Pointers(rods), margin, 1);
    const std::vector<SegmentPair>& kept = list.Pairs(Pointers(rods), margin, 1);
    ASSERT_TRUE(Sorted(kept));
    ASSERT_TRUE(Holds(kept, exact))
        << "call " << call;
    most_pairs = std::max(most_pairs, exact.size());
  }
  EXPECT_GT(most_pairs, 10u);  // the soup has pairs to keep
  // Found again every few calls (up to 0.05 of margin per call and coordinate on average), not at
  // every call, and not only once.
  EXPECT_GT(list.searches(), 10);
  EXPECT_LT(list.searches(), calls / 2);
}

TEST(CandidatePairList, SearchesAgainOnAChangeOfRodsMarginOrExclusionAndOnNotANumber) {
  std::mt19937 rng(5);
  std::vector<Matrix3X> rods = RandomSoup(&rng, 4, 10, 4.0);
  CandidatePairList list;
  // Found with the skin (the margin grown by half of it), kept while nothing moves.
  EXPECT_EQ(list.Pairs(Pointers(rods), 0.2, 1), FindCandidatePairs(Pointers(rods), 0.3, 1));
  list.Pairs(Pointers(rods), 0.2, 1);
  EXPECT_EQ(list.searches(), 1);
  list.Pairs(Pointers(rods), 0.3, 1);  // a new margin: found again (the last list served 2 calls)
  EXPECT_EQ(list.searches(), 2);
  // A new exclusion: found again; the last list served one call only, so without the skin.
  EXPECT_EQ(list.Pairs(Pointers(rods), 0.3, 2), FindCandidatePairs(Pointers(rods), 0.3, 2));
  EXPECT_EQ(list.searches(), 3);
  rods.pop_back();  // fewer rods
  EXPECT_EQ(list.Pairs(Pointers(rods), 0.3, 2), FindCandidatePairs(Pointers(rods), 0.3, 2));
  EXPECT_EQ(list.searches(), 4);
  rods[0](1, 3) = std::numeric_limits<double>::quiet_NaN();  // not a number: found again
  EXPECT_EQ(list.Pairs(Pointers(rods), 0.3, 2), FindCandidatePairs(Pointers(rods), 0.3, 2));
  list.Pairs(Pointers(rods), 0.3, 2);  // a node that is not a number differs from itself
  EXPECT_EQ(list.searches(), 6);
}

// Rods that move by more than the margin per call: every call searches, first with the skin, then
// (the list having served one call) without it for 8 searches, then with it again; each call's
// pairs hold FindCandidatePairs'.
TEST(CandidatePairList, LargeMotionsSearchWithoutTheSkin) {
  std::mt19937 rng(8);
  std::vector<Matrix3X> rods = RandomSoup(&rng, 8, 15, 8.0);
  const double margin = 0.2;
  CandidatePairList list;
  std::vector<bool> with_skin;
  for (int call = 0; call < 20; ++call) {
    for (Matrix3X& x : rods) x.colwise() += Vec3(0.0, 0.0, 0.5 * margin * (call % 2 == 0 ? 1 : -1));
    for (Matrix3X& x : rods) x.col(0).x() += 2.0 * margin;  // one node moves by more than s/2
    const std::vector<SegmentPair>& kept = list.Pairs(Pointers(rods), margin, 1);
    const std::vector<SegmentPair> exact = FindCandidatePairs(Pointers(rods), margin, 1);
    ASSERT_TRUE(Holds(kept, exact));
    with_skin.push_back(kept == FindCandidatePairs(Pointers(rods), 1.5 * margin, 1) &&
                        kept != exact);
    EXPECT_EQ(list.searches(), call + 1);
  }
  // Calls 0, 9 and 18 with the skin (a pair list that differs from the exact one), the others not.
  for (int call = 0; call < 20; ++call)
    EXPECT_EQ(with_skin[static_cast<std::size_t>(call)], call % 9 == 0) << "call " << call;
}

}  // namespace
}  // namespace stokesrods
