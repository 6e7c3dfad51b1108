// [[bodies]], [wall] and the rods' `body` key (SPEC "Additions"): read, echoed, and refused with
// the file, the key and the problem when they cannot run.
#include <gtest/gtest.h>

#include <string>

#include "stokesrods/io/build_model.h"
#include "stokesrods/io/config.h"
#include "common/model_from_toml.h"

namespace stokesrods {
namespace {

constexpr char kRun[] = "[run]\nduration = 0.5\ntime_step = 0.01\n";
// A helix hanging below z = 0 (its nodes reach z = −0.1), R = 8 mm.
constexpr char kRod[] = "[[rods]]\nnodes = 21\naxis_length = 0.1\nhelix_radius = 0.008\n";


void ExpectError(const std::string& text, const std::string& expected) {
  const std::string error = testing::ConfigErrorOf(text);
  EXPECT_NE(error.find(expected), std::string::npos)
      << "input:\n" << text << "\nerror: " << error << "\nexpected: " << expected;
}

TEST(BodiesConfig, WallIsReadNormalizedAndEchoed) {
  const Config c = ParseConfig(std::string(kRun) + kRod +
                                   "[wall]\npoint = [0.0, 0.0, -0.2]\nnormal = [0.0, 0.0, 2.0]\n",
                               "case.toml");
  ASSERT_TRUE(c.wall.has_value());
  EXPECT_EQ(c.wall->normal, Vec3(0, 0, 1));
  EXPECT_EQ(c.wall->point, Vec3(0, 0, -0.2));
  const Model m = BuildModel(c);
  ASSERT_TRUE(m.fluid.wall.has_value());
  EXPECT_EQ(m.fluid.wall->point, Vec3(0, 0, -0.2));
  // The echo reads back to the same configuration.
  const Config again = ParseConfig(ConfigToToml(c), "echo.toml");
  ASSERT_TRUE(again.wall.has_value());
  EXPECT_EQ(again.wall->normal, c.wall->normal);
  EXPECT_NE(ConfigToJson(c).find("\"wall\""), std::string::npos);
  EXPECT_FALSE(ParseConfig(std::string(kRun) + kRod, "case.toml").wall.has_value());
  // The matrix-free mobility takes the wall (its images as sources: fluid/wall_sources.h).
  const Model mf = BuildModel(ParseConfig(std::string(kRun) + kRod +
                                              "[fluid]\nmobility = \"matrix_free\"\n"
                                              "[wall]\npoint = [0.0, 0.0, -0.2]\n",
                                          "case.toml"));
  EXPECT_EQ(mf.hydro.mobility.kind, MobilityKind::kMatrixFree);
  ASSERT_TRUE(mf.fluid.wall.has_value());
  // "auto" with a wall chooses as without one: matrix-free above 500 nodes.
  const std::string big = "[[rods]]\nnodes = 501\naxis_length = 0.5\nhelix_radius = 0.008\n";
  for (const bool wall : {false, true}) {
    const Model m_auto = BuildModel(ParseConfig(
        std::string(kRun) + big + (wall ? "[wall]\npoint = [0.0, 0.0, -0.6]\n" : ""), "case.toml"));
    EXPECT_EQ(m_auto.hydro.mobility.kind, MobilityKind::kMatrixFree) << "wall " << wall;
  }
}

TEST(BodiesConfig, BodiesAreReadAndEchoedWithOverrides) {
  const std::string text = std::string(kRun) + kRod +
                           "[[bodies]]\nradius = 0.01\ncenter = [0.0, 0.05, 0.0]\n"
                           "motion = \"prescribed\"\nvelocity = [0.0, 0.0, 1e-3]\n";
  const Config c = ParseConfig(text, "case.toml", {"bodies.1.surface_points=200"});
  ASSERT_EQ(c.bodies.size(), 1u);
  EXPECT_EQ(c.bodies[0].motion, "prescribed");
  EXPECT_EQ(c.bodies[0].surface_points, 200);
  EXPECT_EQ(c.bodies[0].velocity, Vec3(0, 0, 1e-3));
  const Config again = ParseConfig(ConfigToToml(c), "echo.toml");
  ASSERT_EQ(again.bodies.size(), 1u);
  EXPECT_EQ(again.bodies[0].center, c.bodies[0].center);
  EXPECT_EQ(again.bodies[0].surface_points, 200);
  EXPECT_NE(testing::ConfigErrorOf(text, {"bodies.2.radius=1"}).find("bodies.2.radius: body 2 does not exist"),
            std::string::npos);
}

TEST(BodiesConfig, BadBodiesAndWallsAreRefusedNamingTheKey) {
  const std::string base = std::string(kRun) + kRod;
  const std::string body = "[[bodies]]\nradius = 0.01\ncenter = [0.0, 0.05, 0.0]\n";
  ExpectError(base + "[[bodies]]\nradius = -1.0\n", "case.toml: bodies.1.radius: must be a finite number > 0");
  ExpectError(base + "[[bodies]]\nshape = \"cube\"\n", "bodies.1.shape: \"cube\" is not one of");
  ExpectError(base + "[[bodies]]\nmotion = \"wander\"\n", "bodies.1.motion: \"wander\" is not one of");
  ExpectError(base + "[[bodies]]\nvelocity = [1.0, 0.0, 0.0]\n",
              "bodies.1.velocity: only for motion = \"prescribed\"");
  ExpectError(base + "[[bodies]]\ncolour = 1\n", "bodies.1.colour: unknown key");
  ExpectError(base + body + "force = [0.0, 0.0, -1.0]\n", "bodies.1.force: only for motion = \"free\"");
  ExpectError(base + body + "half_length = 0.02\n", "bodies.1.half_length: only for shape = \"spheroid\"");
  const std::string spheroid = body + "shape = \"spheroid\"\nhalf_length = 0.02\n";
  ExpectError(base + spheroid, "bodies.1.shape: a \"spheroid\" takes no contact yet");
  ExpectError(base + "[contact]\nenabled = false\n" + body + "shape = \"spheroid\"\n",
              "bodies.1.half_length: a spheroid needs a finite polar semi-axis > 0");
  ExpectError(base + "[contact]\nenabled = false\n" + spheroid + "axis = [0.0, 0.0, 0.0]\n",
              "bodies.1.axis: must not be the zero vector");
  ExpectError(std::string(kRun) + "[contact]\nenabled = false\n" + kRod + "body = 1\n" + spheroid,
              "rods.1.body: body 1 is a spheroid: rods are clamped on spheres only yet");
  ExpectError(base + body + "motion = \"free\"\ntorque = [0.0, 0.0, inf]\n", "bodies.1.torque: must be finite");
  ExpectError(base + body + "surface_points = 3\n", "bodies.1.surface_points: must be between 20");
  ExpectError(base + "[fluid]\nmodel = \"lsbt\"\n" + body, "bodies.1: bodies need fluid.model = \"rss\"");
  ExpectError(base + "[wall]\nnormal = [0.0, 0.0, 0.0]\n", "case.toml: wall.normal: must not be the zero vector");
  ExpectError(base + "[wall]\nnormal = [0.0, 0.0, 1.0]\nside = 1\n", "wall.side: unknown key");
  ExpectError(base + "[fluid]\nmodel = \"rft\"\n[wall]\npoint = [0.0, 0.0, -1.0]\n",
              "case.toml: wall: fluid.model = \"rft\" has no wall");
  ExpectError(base + "[fluid]\nmodel = \"lsbt\"\n[wall]\npoint = [0.0, 0.0, -1.0]\n",
              "case.toml: wall: fluid.model = \"lsbt\" has no wall");
  ExpectError(base + "[wall]\npoint = [0.0, 0.0, -0.05]\n",
              "case.toml: rods.1.base: rod 1 crosses or touches the wall");
  ExpectError("[[rods]]\nnodes = 21\naxis_length = 0.1\nhelix_radius = 0.008\nbody = 2\n" +
                  std::string(kRun) + body,
              "rods.1.body: body 2 does not exist");
}

TEST(BodiesConfig, BodiesOverlappingRodsEachOtherOrTheWallAreRefused) {
  const std::string base = std::string(kRun) + kRod;
  ExpectError(base + "[[bodies]]\nradius = 0.01\ncenter = [0.0, 0.0, -0.05]\n",
              "case.toml: rods.1.base: rod 1 enters body 1 at the start");
  ExpectError(base + "[[bodies]]\nradius = 0.01\ncenter = [0.0, 0.05, 0.0]\n"
                     "[[bodies]]\nradius = 0.01\ncenter = [0.0, 0.06, 0.0]\n",
              "case.toml: bodies.2.center: body 2 overlaps body 1");
  ExpectError(base + "[[bodies]]\nradius = 0.01\ncenter = [0.0, 0.05, -0.195]\n"
                     "[wall]\npoint = [0.0, 0.0, -0.2]\n",
              "case.toml: bodies.1.center: body 1 crosses or touches the wall");
  // A rod on a body starts at its surface.
  ExpectError("[[rods]]\nnodes = 21\naxis_length = 0.1\nhelix_radius = 0.008\nbody = 1\n" +
                  std::string(kRun) + "[[bodies]]\nradius = 0.01\ncenter = [0.0, 0.0, 0.05]\n",
              "rods.1.base: rod 1 is on body 1 but its node 0 is 0.04 m from the body's surface");
}

}  // namespace
}  // namespace stokesrods
