#include "iblkit/capture/folder.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"

using namespace ibl;
using namespace ibl::capture;

namespace {

namespace fs = std::filesystem;

CaptureFolder example() {
  CaptureFolder c;
  c.backplate = "backplate.jpg";
  c.board_spec = "checker:9x6:0.08";
  c.board = parse_board(c.board_spec, "board");
  place_board(c.board, {-0.87, 0, 0.95}, {1, 0, 0}, {0, 0, -1}, "board");
  c.ball_center = {0, 0.15, 0};
  c.ball_radius = 0.05;
  c.facing = {0.6, 0.2, 0.8};
  c.views = {{{"view0_e0.jpg", "view0_e1.jpg"}, 0, std::nullopt, 10, 0, 0},
             {{"view1_e0.jpg", "view1_e1.jpg"}, 90, BallCircle{128, 128, 115}, 10, 0, 0}};
  c.proxy = "proxy.obj";
  c.object_at = {0.1, 0.15, -0.1};
  c.truth = "truth.jpg";
  return c;
}

fs::path write(const nlohmann::json& j, const std::string& name) {
  fs::path d = fs::path(::testing::TempDir()) / ("capture_" + name);
  fs::create_directories(d);
  write_json_file((d / "capture.json").string(), j);
  return d;
}

void refused(nlohmann::json j, const std::string& name, const char* words) {
  fs::path d = write(j, name);
  try {
    read_capture(d.string());
    ADD_FAILURE() << name << ": accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("capture.json"), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(CaptureFolder, RoundTripsAndResolvesPathsInTheFolder) {
  const fs::path d = write(capture_to_json(example()), "roundtrip");
  const CaptureFolder c = read_capture(d.string());
  EXPECT_EQ(c.dir, d.string());
  EXPECT_EQ(c.at(c.backplate), (d / "backplate.jpg").string());
  EXPECT_EQ(c.at("/abs/x.jpg"), "/abs/x.jpg");
  EXPECT_EQ(c.board.cols, 9);
  EXPECT_NEAR(c.board.origin.x, -0.87, 1e-12);
  EXPECT_NEAR(c.board.v.z, -1, 1e-12);
  ASSERT_EQ(c.views.size(), 2u);
  EXPECT_FALSE(c.views[0].ball);
  ASSERT_TRUE(c.views[1].ball);
  EXPECT_EQ(c.views[1].ball->r, 115);
  EXPECT_EQ(c.views[1].angle_deg, 90);
  EXPECT_EQ(c.truth, "truth.jpg");
  EXPECT_NEAR(c.object_at.x, 0.1, 1e-12);
  // The manifest itself may be named too.
  EXPECT_EQ(read_capture((d / "capture.json").string()).backplate, "backplate.jpg");
}

TEST(CaptureFolder, BallFrameTurnsViewZeroIntoTheWorld) {
  // from-ball's frame has the camera on +Z and +Y up: its +Z is the facing direction, +X stays level.
  const Vec3 f = normalize(Vec3{0.6, 0.2, 0.8});
  const Mat3 R = ball_frame(f);
  const Vec3 z = R * Vec3{0, 0, 1}, x = R * Vec3{1, 0, 0}, y = R * Vec3{0, 1, 0};
  EXPECT_NEAR(length(z - f), 0, 1e-12);
  EXPECT_NEAR(x.y, 0, 1e-12);
  EXPECT_GT(y.y, 0.9);
  EXPECT_NEAR(dot(cross(x, y), z), 1, 1e-12);  // right-handed
  EXPECT_THROW(ball_frame({0, 1, 0}), Error);
}

TEST(CaptureFolder, BadManifestsNameTheFieldAndTheFile) {
  const nlohmann::json good = capture_to_json(example());
  nlohmann::json j = good;
  j.erase("board");
  refused(j, "noboard", "\"board\" is missing");
  j = good;
  j["board"]["spec"] = "checker:8x6:0.08";
  refused(j, "symmetric", "board");
  j = good;
  j["ball"]["views"] = nlohmann::json::array();
  refused(j, "noviews", "one or two views");
  j = good;
  j["ball"]["views"][0].erase("distance_radii");
  refused(j, "nodistance", "distance_radii");
  j = good;
  j["ball"]["center"] = {0, "x", 0};
  refused(j, "center", "\"center\" must be [x, y, z]");
  j = good;
  j["ball"]["radius"] = -1;
  refused(j, "radius", "\"radius\"");
  j = good;
  j["format"] = "iblkit.probes/1";
  refused(j, "format", "iblkit.capture/1");
  j = good;
  j["ball"]["facing"] = {0, 1, 0};
  refused(j, "facing", "facing");
  j = good;
  j["object"]["at"] = {1e30, 0, 0};
  refused(j, "far", "object.at");
}
