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

}  // namespace
}  // namespace ibl::geometry
