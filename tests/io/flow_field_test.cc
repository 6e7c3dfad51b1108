// The flow-field writer with the dense and the matrix-free mobility: the same velocities on the
// plane (the matrix-free solve is GMRES at 1e-10 with the far field at its tolerance, 1e-8 per
// interaction; we allow 1e-6 of the largest speed).
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "common/model_from_toml.h"
#include "common/small_helices.h"
#include "stokesrods/io/flow_field.h"
#include "stokesrods/sim/integrator.h"
#include "common/scratch_dir.h"

namespace stokesrods {
namespace {

std::vector<double> ReadSpeeds(const std::string& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);  // header
  std::vector<double> values;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::string cell;
    for (int column = 0; std::getline(s, cell, ','); ++column)
      if (column >= 3) values.push_back(std::stod(cell));
  }
  return values;
}

std::vector<double> FlowWith(const std::string& mobility, const std::string& dir,
                             const std::string& extra = "") {
  const Model model = testing::ModelFromToml(testing::SmallHelicesToml(
      2, 21, 300, "model = \"rss\"\nmobility = \"" + mobility + "\"\n" + extra));
  State state = MakeRestState(model);
  Workspace ws(model);
  for (int k = 0; k < 10; ++k) EXPECT_TRUE(Step(model, 0.01, &state, &ws).ok);
  FlowFieldConfig plane;
  plane.origin = Vec3(-0.02, 0.0, -0.12);
  plane.u = Vec3(0.06, 0.0, 0.0);
  plane.v = Vec3(0.0, 0.0, 0.13);
  plane.resolution = {7, 9};
  const std::string name = WriteFlowField(model, state, plane, dir, 0);
  return ReadSpeeds((std::filesystem::path(dir) / "flow" / "flow_00000.csv").string());
}

// The matrix-free operator's far field at 1e-8 against the dense 𝕄 within 1e-6 of the largest
// speed, and at its default accuracy (1e-4) within 1e-4.
TEST(FlowField, MatrixFreeMatchesDense) {
  const std::string base = testing::ScratchPath("stokesrods_flow_test").string();
  const std::vector<double> dense = FlowWith("dense", base + "/dense");
  for (const auto& [extra, bound] :
       {std::pair<std::string, double>{"fast_sum_tolerance = 1e-8", 1e-6}, {"", 1e-4}}) {
    const std::vector<double> free = FlowWith("matrix_free", base + "/free", extra);
    ASSERT_EQ(dense.size(), free.size());
    ASSERT_EQ(dense.size(), 3u * 7u * 9u);
    double largest = 0.0, difference = 0.0;
    for (std::size_t i = 0; i < dense.size(); ++i) {
      largest = std::max(largest, std::abs(dense[i]));
      difference = std::max(difference, std::abs(dense[i] - free[i]));
    }
    std::printf("flow field (%s): largest speed component %.3e m/s, matrix-free − dense %.3e\n",
                extra.c_str(), largest, difference);
    EXPECT_GT(largest, 0.0);
    EXPECT_LT(difference, bound * largest);
  }
}

}  // namespace
}  // namespace stokesrods
