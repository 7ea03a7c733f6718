#include "iblkit/capture/camera_solve.h"

#include <cmath>

#include <gtest/gtest.h>

#include "iblkit/core/error.h"
#include "iblkit/io/photo.h"

using namespace ibl;
using namespace ibl::capture;

namespace {

nlohmann::json six_points() {
  std::vector<Correspondence> p;
  for (int i = 0; i < 6; ++i) p.push_back({{10.5 + i, 20.25 * i}, {0.1 * i, 0, -0.2 * (i % 3)}});
  return points_to_json(p);
}

void refused(const nlohmann::json& j, const char* word) {
  try {
    points_from_json(j, "pts.json");
    ADD_FAILURE() << "accepted " << j.dump();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("pts.json"), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(CameraSolve, PointsFilesRoundTripAndAreChecked) {
  auto pts = points_from_json(six_points(), "pts.json");
  ASSERT_EQ(pts.size(), 6u);
  EXPECT_EQ(pts[3].pixel.x, 13.5);
  EXPECT_EQ(pts[3].pixel.y, 60.75);
  EXPECT_EQ(pts[2].world.z, -0.4);
  auto j = six_points();
  j["points"].erase(0);
  refused(j, "at least 6");
  j = six_points();
  j["points"][1]["pixel"] = {1.0};
  refused(j, "points[1].pixel");
  j = six_points();
  j["points"][2]["world"][1] = std::nan("");  // nlohmann writes NaN as null: not a number
  refused(j, "points[2].world");
  j = six_points();
  j["points"][2]["world"][1] = 1e9;
  refused(j, "points[2].world");
  j = six_points();
  j["format"] = "iblkit.camera/1";
  refused(j, "iblkit.points/1");
}

TEST(CameraSolve, BoardsAreParsedPlacedAndChecked) {
  Board b = parse_board("checker:9x6:0.05", "--board");
  EXPECT_EQ(b.cols, 9);
  EXPECT_EQ(b.rows, 6);
  EXPECT_EQ(b.square, 0.05);
  place_board(b, {1, 0, 2}, {2, 0, 0}, {0.1, 0, -1}, "--board-axes");
  Vec3 c = b.corner(2, 1);
  EXPECT_NEAR(c.x, 1.1, 1e-12);
  EXPECT_NEAR(c.z, 1.95, 1e-12);
  EXPECT_EQ(b.corners().size(), 54u);
  EXPECT_NEAR(dot(b.u, b.v), 0, 1e-15);
  for (const char* bad : {"checker:9x6", "checker:6x6:0.05", "checker:9x7:0.05", "checker:2x5:0.05", "checker:9x6:0",
                          "charuco:9x6:0.05", "checker:9x6:0.05x"})
    EXPECT_THROW(parse_board(bad, "--board"), Error) << bad;
  EXPECT_THROW(place_board(b, {0, 0, 0}, {1, 0, 0}, {2, 0, 0}, "--board-axes"), Error);
}

TEST(CameraSolve, CharucoBoardsCountSquaresAndNameTheirDictionary) {
  Board b = parse_board("charuco:5x4:0.2:0.15", "--board");
  EXPECT_TRUE(b.charuco);
  EXPECT_EQ(b.cols, 4);  // inner corners: one fewer than the squares
  EXPECT_EQ(b.rows, 3);
  EXPECT_EQ(b.marker, 0.15);
  EXPECT_EQ(b.dictionary_name, "4x4_50");
  EXPECT_EQ(b.dictionary, 0);  // cv::aruco::DICT_4X4_50
  EXPECT_EQ(b.describe(), "5x4-square ChArUco board");
  Board c = parse_board("charuco:12x9:0.03:0.022:5x5_100", "--board");
  EXPECT_EQ(c.dictionary, 5);  // DICT_5X5_100
  EXPECT_EQ(parse_board("checker:7x4:0.1", "--board").describe(), "7x4-corner chessboard");
  // Squares out of range, a marker no smaller than its square, a dictionary unknown or too small for the board's
  // 11·9/2 = 49… (12·10/2 = 60 > 50) markers, a tail.
  for (const char* bad :
       {"charuco:2x4:0.2:0.15", "charuco:5x4:0.2:0.2", "charuco:5x4:0.2:0", "charuco:5x4:0.2:0.15:3x3_50",
        "charuco:12x10:0.03:0.02", "charuco:5x4:0.2:0.15x", "charuco:5x4:0.2:0.15:"}) {
    try {
      parse_board(bad, "--board");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("--board " + std::string(bad)), std::string::npos) << e.what();
    }
  }
}

TEST(CameraSolve, ReprojectionCountsPointsBehindTheCamera) {
  geometry::Camera c;
  c.width = 64;
  c.height = 48;
  std::vector<Correspondence> pts;
  for (Vec3 w : {Vec3{0, 0, 0}, Vec3{0.1, 0.2, 0}, Vec3{0, 0.3, 5}}) {
    auto q = c.project(w);
    pts.push_back({q ? *q + Vec2{0.3, 0.4} : Vec2{0, 0}, w});
  }
  Reprojection r = reprojection(c, pts);
  EXPECT_EQ(r.behind, 1);  // (0, 0.3, 5) is behind the default eye at z = 1.2
  EXPECT_NEAR(r.rms_px, 0.5, 1e-9);
  EXPECT_NEAR(r.max_px, 0.5, 1e-9);
}

TEST(CameraSolve, ExifLensRoundTripsThroughAJpeg) {
  // The attributes the lab writes give the field of view back: exactly from FocalLength and the focal plane's
  // resolution, to about a percent from the 35 mm equivalent alone.
  for (double fov : {20.0, 50.0, 93.5}) {
    io::PhotoMeta m;
    m.attributes = exif_lens_attributes(fov, 320, 240);
    auto l = lens_from_exif(m, 320, 240);
    ASSERT_TRUE(l);
    EXPECT_NEAR(l->fov_y_deg, fov, 1e-6) << l->source;
    io::PhotoMeta m35;
    for (const auto& a : m.attributes)
      if (a.name == "Exif:FocalLengthIn35mmFilm") m35.attributes.push_back(a);
    auto l35 = lens_from_exif(m35, 320, 240);
    ASSERT_TRUE(l35);
    EXPECT_NEAR(l35->fov_y_deg, fov, 0.02 * fov) << l35->source;
  }
  EXPECT_FALSE(lens_from_exif({}, 320, 240));
  // Through OpenImageIO's JPEG writer and reader (the Exif block), as `lab shoot --backplate` writes it.
  const std::string path = ::testing::TempDir() + "exif_lens.jpg";
  io::PhotoMeta m;
  m.exposure_time = 0.01;
  m.attributes = exif_lens_attributes(50, 320, 240);
  io::write_photo(path, Image(320, 240, 3), 8, m, 90);
  auto back = lens_from_exif(io::read_photo(path).meta, 320, 240);
  ASSERT_TRUE(back);
  EXPECT_NEAR(back->fov_y_deg, 50, 1e-3) << back->source;
  // A rational written out by OpenImageIO ("49/2") reads as its value.
  io::PhotoMeta r;
  r.attributes = {{"Exif:FocalLength", "rational", "49/2"},
                  {"Exif:FocalPlaneXResolution", "rational", "1000/1"},
                  {"Exif:FocalPlaneResolutionUnit", "int", "4"}};
  auto lr = lens_from_exif(r, 320, 240);
  ASSERT_TRUE(lr);
  EXPECT_NEAR(lr->fov_y_deg, 2 * std::atan(120 / 24500.0) * 180 / kPi, 1e-9);
}
