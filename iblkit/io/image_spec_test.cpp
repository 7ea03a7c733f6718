#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "iblkit/core/error.h"
#include "iblkit/io/image_io.h"

namespace ibl::io {
namespace {

namespace fs = std::filesystem;

fs::path spec_dir() {
  fs::path d = fs::temp_directory_path() / ("iblkit_spec_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

ErrorKind kind_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.kind();
  }
  ADD_FAILURE() << "no error thrown";
  return ErrorKind::Internal;
}

TEST(ImageSpec, SizeAndChannelsOfEveryFormat) {
  auto d = spec_dir();
  for (const char* ext : {".exr", ".pfm", ".hdr", ".png", ".tif"}) {
    std::string p = (d / (std::string("s") + ext)).string();
    int nc = std::string(ext) == ".exr" || std::string(ext) == ".tif" ? 4 : 3;
    write_image(p, Image(13, 7, nc, 0.25f));
    ImageSpec s = read_image_spec(p);
    EXPECT_EQ(s.width, 13) << ext;
    EXPECT_EQ(s.height, 7) << ext;
    EXPECT_EQ(s.channels, nc) << ext;
  }
  fs::remove_all(d);
}

// The header alone is read: a file whose pixel data is cut off still gives its size, where
// read_image fails on the pixels.
TEST(ImageSpec, ReadsTheHeaderNotThePixels) {
  auto d = spec_dir();
  std::string full = (d / "full.pfm").string(), cut = (d / "cut.pfm").string();
  write_image(full, Image(64, 32, 3, 1.0f));
  std::ifstream in(full, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, 64);
  ImageSpec s = read_image_spec(cut);
  EXPECT_EQ(s.width, 64);
  EXPECT_EQ(s.height, 32);
  EXPECT_THROW(read_image(cut), Error);
  fs::remove_all(d);
}

TEST(ImageSpec, BadFilesFailLikeReadImage) {
  auto d = spec_dir();
  EXPECT_EQ(kind_of([&] { read_image_spec((d / "nothere.exr").string()); }), ErrorKind::Io);
  EXPECT_EQ(kind_of([&] { read_image_spec(d.string()); }), ErrorKind::Io);
  std::ofstream(d / "notes.exr") << "not an image at all\n";
  EXPECT_EQ(kind_of([&] { read_image_spec((d / "notes.exr").string()); }), ErrorKind::Format);
  EXPECT_EQ(kind_of([&] { read_image((d / "notes.exr").string()); }), ErrorKind::Format);
  fs::remove_all(d);
}

}  // namespace
}  // namespace ibl::io
