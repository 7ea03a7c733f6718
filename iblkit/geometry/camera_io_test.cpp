#include "iblkit/geometry/camera_io.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "iblkit/core/error.h"

namespace ibl::geometry {
namespace {

Camera looking_down() {
  Camera c;
  c.eye = {0, 3, 0};
  c.target = {0, 0, 0};
  c.up = {0, 0, -1};
  c.fov_y_deg = 60;
  c.width = 64;
  c.height = 48;
  return c;
}

TEST(GeometryCameraIo, JsonRoundTripAndErrors) {
  const Camera c = looking_down();
  const Camera back = camera_from_json(camera_to_json(c), "test");
  EXPECT_EQ(back.eye.y, 3);
  EXPECT_EQ(back.up.z, -1);
  EXPECT_EQ(back.fov_y_deg, 60);
  EXPECT_EQ(back.width, 64);
  EXPECT_EQ(back.height, 48);
  const auto path = (std::filesystem::temp_directory_path() / "geometry_test_camera.json").string();
  write_camera(path, c, false);
  const Camera r = read_camera(path);
  EXPECT_EQ(r.width, 0);  // no size in the file: the photograph's
  EXPECT_EQ(r.target.x, 0);
  std::filesystem::remove(path);
  nlohmann::json j = camera_to_json(c);
  j["fov_y_deg"] = 190;
  EXPECT_THROW(camera_from_json(j, "test"), Error);
  j = camera_to_json(c);
  j["format"] = "iblkit.sh/1";
  EXPECT_THROW(camera_from_json(j, "test"), Error);
  j = camera_to_json(c);
  j["target"] = j["eye"];
  EXPECT_THROW(camera_from_json(j, "test"), Error);
}

// A width of 2^32 + 64 must not be narrowed to 64: integers are range-checked before narrowing.
TEST(GeometryCameraIo, HugeWidthIsRefusedNotNarrowed) {
  nlohmann::json j = camera_to_json(looking_down());
  j["width"] = (int64_t{1} << 32) + 64;
  try {
    camera_from_json(j, "cam.json");
    FAIL() << "a width of 2^32 + 64 was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("width"), std::string::npos) << e.what();
  }
  j["width"] = -64;
  EXPECT_THROW(camera_from_json(j, "cam.json"), Error);
}

TEST(GeometryCameraIo, IntrinsicsAndDistortionRoundTrip) {
  Camera c = looking_down();
  c.width = 640;
  c.height = 480;
  c.intrinsics = Intrinsics{501.25, 499.5, 322.125, 238.75};
  c.distortion = {-0.21, 0.043, 0.0011, -0.0007, -0.0032};
  const auto path = (std::filesystem::temp_directory_path() / "geometry_test_camera_lens.json").string();
  write_camera(path, c, false);  // with intrinsics the size is written anyway
  const Camera r = read_camera(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(r.intrinsics);
  EXPECT_EQ(r.width, 640);
  EXPECT_EQ(r.height, 480);
  EXPECT_EQ(r.intrinsics->fx, 501.25);
  EXPECT_EQ(r.intrinsics->fy, 499.5);
  EXPECT_EQ(r.intrinsics->cx, 322.125);
  EXPECT_EQ(r.intrinsics->cy, 238.75);
  EXPECT_EQ(r.distortion.k1, -0.21);
  EXPECT_EQ(r.distortion.k2, 0.043);
  EXPECT_EQ(r.distortion.p1, 0.0011);
  EXPECT_EQ(r.distortion.p2, -0.0007);
  EXPECT_EQ(r.distortion.k3, -0.0032);
  for (double px : {0.5, 320.0, 639.5}) EXPECT_LT(length(r.ray_direction(px, 17) - c.ray_direction(px, 17)), 1e-15);
  // An old file (no lens) reads as the pinhole, and writes no lens back.
  const Camera old = camera_from_json(camera_to_json(looking_down()), "old");
  EXPECT_FALSE(old.intrinsics);
  EXPECT_FALSE(camera_to_json(old).contains("intrinsics"));
  EXPECT_FALSE(camera_to_json(old).contains("distortion"));
  // fov_y_deg may be left out when the intrinsics give it.
  nlohmann::json j = camera_to_json(c);
  j.erase("fov_y_deg");
  EXPECT_NEAR(camera_from_json(j, "t").fov_y_deg, 2 * std::atan(240 / 499.5) * 180 / kPi, 1e-12);
}

TEST(GeometryCameraIo, BadLensesAreRefusedNamingTheField) {
  Camera c = looking_down();
  c.intrinsics = Intrinsics{50, 50, 32, 24};
  c.distortion = {-0.2, 0, 0, 0, 0};
  auto refused = [](nlohmann::json j, const char* word) {
    try {
      camera_from_json(j, "cam.json");
      ADD_FAILURE() << "accepted " << j.dump();
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("cam.json"), std::string::npos) << e.what();
    }
  };
  nlohmann::json j = camera_to_json(c);
  j["intrinsics"]["fx"] = -50;
  refused(j, "focal");
  j = camera_to_json(c);
  j["intrinsics"].erase("cy");
  refused(j, "cy");
  j = camera_to_json(c);
  j["intrinsics"]["cx"] = 1e9;
  refused(j, "principal point");
  j = camera_to_json(c);
  j["distortion"] = {0.1, 0.2};
  refused(j, "distortion");
  j = camera_to_json(c);
  j["distortion"][0] = 1e5;
  refused(j, "distortion");
  j = camera_to_json(c);
  j["distortion"][1] = "x";
  refused(j, "distortion");
  j = camera_to_json(c);
  j.erase("intrinsics");
  refused(j, "intrinsics");
  j = camera_to_json(c);
  j.erase("width");
  refused(j, "width");
}

}  // namespace
}  // namespace ibl::geometry
