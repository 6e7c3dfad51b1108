// The self-contact exclusion of a rod (sim/contact_forces.h): how many edges apart two of its
// segments must be to be tested against each other.
#include "stokesrods/sim/contact_forces.h"

#include <gtest/gtest.h>

#include "stokesrods/sim/model.h"

namespace stokesrods {
namespace {

RodModel Rod(double radius, int edges, double edge_length) {
  RodModel rod;
  rod.radius = radius;
  rod.rest_edge_length = VecX::Constant(edges, edge_length);
  return rod;
}

TEST(SelfContactExclusion, SpansTheEdgesOneDiameterCovers) {
  // 2r / shortest edge, rounded up, plus the adjacent edge: the paper's rod (r = 1 mm on edges of
  // 4.5 mm) excludes its neighbours only; r = 5 mm on the same edges excludes 4 edges each way.
  EXPECT_EQ(SelfContactExclusion(Rod(1e-3, 64, 4.5e-3)), 2);
  EXPECT_EQ(SelfContactExclusion(Rod(5e-3, 64, 4.5e-3)), 4);
  EXPECT_EQ(SelfContactExclusion(Rod(4.5e-3, 64, 4.5e-3)), 3);
}

TEST(SelfContactExclusion, IsAtMostTheRodsEdgeCount) {
  // A radius far beyond the edges (found by the configuration fuzzer: 1e7 m on 5 mm edges; the
  // count then overflowed an int): no pair of the rod's own segments is tested.
  EXPECT_EQ(SelfContactExclusion(Rod(1e7, 40, 5e-3)), 40);
  EXPECT_EQ(SelfContactExclusion(Rod(0.1, 40, 5e-3)), 40);
  EXPECT_EQ(SelfContactExclusion(Rod(1e-3, 1, 5e-3)), 1);
}

}  // namespace
}  // namespace stokesrods
