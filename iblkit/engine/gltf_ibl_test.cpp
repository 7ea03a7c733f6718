// engine/gltf_ibl.h: EXT_lights_image_based's specular images as files. The PNGs are read back
// through OpenImageIO (raw bytes, alpha unassociated) and decoded here with Babylon.js's formula,
// written out independently of io/rgbd.cpp from Babylon's source:
//   packages/dev/core/src/Shaders/ShadersInclude/helperFunctions.fx (commit 0368dbbe):
//     fromRGBD(rgbd) = toLinearSpace(rgbd.rgb) / rgbd.a,  toLinearSpace(c) = pow(c, 2.2)
//     (LinearEncodePowerApprox = 2.2; the exact sRGB curve only with USE_EXACT_SRGB_CONVERSIONS,
//     an engine option that is off by default),
// with the texture bytes as GL hands them to the shader (byte/255), against the EXR faces they came
// from; the rows as Babylon's loader uploads them (invertY: PNG row r is GL face row S−1−r).
#include "iblkit/engine/gltf_ibl.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/engine/export.h"
#include "iblkit/io/envmap_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/sh/project.h"

namespace ibl::engine {
namespace {

namespace fs = std::filesystem;
const char* kForest = "/usr/share/blender/datafiles/studiolights/world/forest.exr";
const char* kFaces[6] = {"px", "nx", "py", "ny", "pz", "nz"};

fs::path scratch(const std::string& name) {
  fs::path d = fs::temp_directory_path() / fmt::format("iblkit_gltf_ibl_{}_{}", name, ::getpid());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

struct Png {
  int width = 0, height = 0, channels = 0;
  bool uint8 = false;
  std::vector<unsigned char> bytes;
  const unsigned char* at(int x, int y) const { return &bytes[(static_cast<size_t>(y) * width + x) * channels]; }
};
// The bytes of a PNG as stored: OpenImageIO with alpha left unassociated (its default multiplies
// colour by alpha, which is not what a WebGL upload with premultiplyAlpha off sees).
Png read_png(const std::string& path) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) throw std::runtime_error(path + ": " + OIIO::geterror());
  Png p;
  p.width = in->spec().width;
  p.height = in->spec().height;
  p.channels = in->spec().nchannels;
  p.uint8 = in->spec().format == OIIO::TypeDesc::UINT8;
  p.bytes.resize(static_cast<size_t>(p.width) * p.height * p.channels);
  if (!in->read_image(0, 0, 0, p.channels, OIIO::TypeDesc::UINT8, p.bytes.data()))
    throw std::runtime_error(in->geterror());
  return p;
}

// Babylon's fromRGBD on 8-bit texels (see the top of the file).
Vec3 babylon_from_rgbd(const unsigned char* px) {
  const double a = px[3] / 255.0;
  return {std::pow(px[0] / 255.0, 2.2) / a, std::pow(px[1] / 255.0, 2.2) / a, std::pow(px[2] / 255.0, 2.2) / a};
}
// Tolerance of one channel: the RGBD quantisation bound of io/rgbd.h, restated from its derivation
// (|q − g| ≤ 1/510 on g = (c·k/255)^(1/2.2), times the slope of x^2.2, times 255/k), clamped range.
double tolerance(double c, int k) {
  const double g = std::min(1.0, std::pow(c * k / 255.0, 1 / 2.2));
  return (255.0 / k) * 2.2 * std::pow(std::min(1.0, g + 1 / 510.0), 1.2) / 510.0 + 1e-9 * c;
}

// A chain of 3 levels (8, 4, 2) whose every texel differs: value grows with x, y, face and level,
// and spans 0.01 … 400 (past RGBD's 255), with one hot texel at (1, 0) — near the top-left corner —
// of every face of level 0.
CubeChain asymmetric_chain() {
  CubeChain c;
  for (int m = 0; m < 3; ++m) {
    const int s = 8 >> m;
    Image strip(6 * s, s, 3);
    for (int f = 0; f < 6; ++f)
      for (int y = 0; y < s; ++y)
        for (int x = 0; x < s; ++x) {
          double v = 0.01 * std::pow(1.9, x + 0.5 * y) * (1 + 0.3 * f) / (1 + m);
          strip.set_rgb(f * s + x, y, {v, 0.5 * v, 0.25 * v + 0.01});
        }
    if (m == 0)
      for (int f = 0; f < 6; ++f) strip.set_rgb(f * s + 1, 0, {400, 20, 3});
    c.levels.push_back(strip);
  }
  return c;
}

TEST(GltfIbl, FacesAreRgbdPngsFlippedUpsideDown) {
  fs::path d = scratch("flip");
  CubeChain chain = asymmetric_chain();
  write_cube_faces((d / "faces").string(), chain);
  CubeChain back = read_cube_faces((d / "faces" / "m{level}_{face}.exr").string());
  ASSERT_EQ(back.count(), 3);
  for (int m = 0; m < 3; ++m) ASSERT_EQ(back.levels[m].size(), chain.levels[m].size());

  const std::string gltf = (d / "ibl.gltf").string();
  std::vector<std::string> written = write_gltf_ibl(gltf, sh::Coeffs(3), back);
  ASSERT_EQ(written.size(), 3u * 6 + 1);
  EXPECT_EQ(written.back(), gltf);
  for (int m = 0; m < 3; ++m)
    for (int f = 0; f < 6; ++f) {
      const std::string png = (d / fmt::format("ibl_m{}_{}.png", m, kFaces[f])).string();
      ASSERT_TRUE(fs::exists(png)) << png;
      Png p = read_png(png);
      const int s = 8 >> m;
      ASSERT_EQ(p.width, s);
      ASSERT_EQ(p.height, s);
      ASSERT_EQ(p.channels, 4) << "a 4-channel PNG is what the extension reads as RGBD";
      ASSERT_TRUE(p.uint8);
      Image face = cube_face(chain, m, f);
      for (int y = 0; y < s; ++y)
        for (int x = 0; x < s; ++x) {
          Vec3 got = babylon_from_rgbd(p.at(x, s - 1 - y));  // PNG row s−1−y holds face row y
          Vec3 want = face.rgb(x, y);
          for (int a = 0; a < 3; ++a) {
            double clamped = std::min(want[a], 255.0);
            ASSERT_NEAR(got[a], clamped, tolerance(want[a], p.at(x, s - 1 - y)[3]))
                << png << " texel (" << x << ", " << y << ") channel " << a;
          }
        }
      if (m == 0) {
        // The hot texel (1, 0) of the face is in the PNG's last row, same column: 400 clamps to 255.
        EXPECT_EQ(p.at(1, s - 1)[3], 1);
        EXPECT_EQ(p.at(1, s - 1)[0], 255);
        EXPECT_DOUBLE_EQ(babylon_from_rgbd(p.at(1, s - 1)).x, 255.0);
        EXPECT_LT(babylon_from_rgbd(p.at(1, 0)).x, 1.0);           // the top row is the face's dim bottom row
        EXPECT_LT(babylon_from_rgbd(p.at(s - 2, s - 1)).x, 10.0);  // not mirrored left–right
      }
    }

  // The document: 18 images image/png with the files' names, specularImages 3 × 6 in face order.
  std::ifstream in(gltf);
  nlohmann::json j = nlohmann::json::parse(in);
  const auto& light = j["extensions"]["EXT_lights_image_based"]["lights"][0];
  EXPECT_EQ(light["specularImageSize"], 8);
  ASSERT_EQ(light["specularImages"].size(), 3u);
  ASSERT_EQ(j["images"].size(), 18u);
  for (int m = 0; m < 3; ++m)
    for (int f = 0; f < 6; ++f) {
      const auto& img = j["images"][light["specularImages"][m][f].get<int>()];
      EXPECT_EQ(img["mimeType"], "image/png");
      EXPECT_EQ(img["uri"], fmt::format("ibl_m{}_{}.png", m, kFaces[f]));
    }
  // And the library's own decoder reads the faces back (rows restored) within the same bound.
  Image dec = gltf_specular_face(io::read_image((d / "ibl_m0_pz.png").string()).with_channels(4));
  EXPECT_EQ(dec.width(), 8);
  fs::remove_all(d);
}

TEST(GltfIbl, ForestThroughTheBabylonDecodeMatchesItsExrFaces) {
  if (!fs::exists(kForest)) GTEST_SKIP() << "no " << kForest << " (blender-data)";
  fs::path d = scratch("forest");
  sphere::EnvMap env = io::read_envmap(kForest);
  write_cube_faces((d / "spec").string(), build_cube_chain(env, 32, Mat3::identity(), 3));
  CubeChain chain = read_cube_faces((d / "spec" / "m{level}_{face}.exr").string());
  ASSERT_EQ(chain.count(), 3);
  const std::string gltf = (d / "forest ibl.gltf").string();  // a space: the URIs are percent-encoded
  write_gltf_ibl(gltf, sh::project(env, 3), chain);
  double worst = 0, peak = 0;
  for (int m = 0; m < 3; ++m)
    for (int f = 0; f < 6; ++f) {
      Png p = read_png((d / fmt::format("forest ibl_m{}_{}.png", m, kFaces[f])).string());
      Image face = io::read_image((d / "spec" / fmt::format("m{}_{}.exr", m, kFaces[f])).string());
      const int s = face.width();
      for (int y = 0; y < s; ++y)
        for (int x = 0; x < s; ++x) {
          const unsigned char* px = p.at(x, s - 1 - y);
          Vec3 got = babylon_from_rgbd(px), want = face.rgb(x, y);
          for (int a = 0; a < 3; ++a) {
            ASSERT_NEAR(got[a], std::min(want[a], 255.0), tolerance(want[a], px[3]));
            worst = std::max(worst, std::abs(got[a] - want[a]) / std::max(want[a], 1e-3));
            peak = std::max(peak, want[a]);
          }
        }
    }
  std::ifstream in(gltf);
  nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["images"][0]["uri"], "forest%20ibl_m0_px.png");
  std::printf("forest 32² × 3 levels: peak %.3g, worst relative difference of Babylon's decode %.4f\n", peak, worst);
  fs::remove_all(d);
}

TEST(GltfIbl, BadFaceSetsAreRefused) {
  fs::path d = scratch("bad");
  write_cube_faces((d / "f").string(), asymmetric_chain());
  const std::string pattern = (d / "f" / "m{level}_{face}.exr").string();
  EXPECT_THROW(read_cube_faces((d / "f" / "m{level}.exr").string()), Error);  // no {face}
  fs::remove(d / "f" / "m1_ny.exr");
  try {
    read_cube_faces(pattern);
    ADD_FAILURE() << "a level with 5 faces was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("m1_ny.exr is missing"), std::string::npos) << e.what();
  }
  io::write_image((d / "f" / "m1_ny.exr").string(), Image(4, 2, 3, 1.0f));  // not square
  EXPECT_THROW(read_cube_faces(pattern), Error);
  io::write_image((d / "f" / "m1_ny.exr").string(), Image(2, 2, 3, 1.0f));  // not the level's size
  EXPECT_THROW(read_cube_faces(pattern), Error);
  for (int f = 0; f < 6; ++f)
    io::write_image((d / "f" / fmt::format("m0_{}.exr", kFaces[f])).string(), Image(6, 6, 3, 1.0f));
  EXPECT_THROW(read_cube_faces(pattern), Error);  // level 0 not a power of two
  EXPECT_THROW(read_cube_faces((d / "none" / "m{level}_{face}.exr").string()), Error);
  fs::remove_all(d);
}

TEST(GltfIbl, AFailedWriteLeavesNothing) {
  // The command's OutputTransaction: an image that cannot be written (a folder in its place) fails
  // the export half-way, and every PNG written before it goes again.
  fs::path d = scratch("fail");
  fs::create_directories(d / "ibl_m1_nx.png");
  {
    OutputTransaction tx;
    EXPECT_THROW(write_gltf_ibl((d / "ibl.gltf").string(), sh::Coeffs(3), asymmetric_chain()), Error);
  }
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(d)) left.push_back(e.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"ibl_m1_nx.png"}) << "left: " << left.size() << " entries";
  fs::remove_all(d);
}

}  // namespace
}  // namespace ibl::engine
