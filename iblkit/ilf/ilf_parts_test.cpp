// Tests of the pipeline's parts: manifests and bad input, the bucket store, projection of parallel
// rays, the two repairs, sub-sampling.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "iblkit/core/error.h"
#include "iblkit/core/testing.h"
#include "iblkit/ilf/analytic.h"
#include "iblkit/ilf/build.h"
#include "iblkit/io/image_io.h"

using ibl::test_util::expect_error;

namespace ibl::ilf {
namespace {
namespace fs = std::filesystem;

std::string temp_dir(const std::string& name) {
  auto d = fs::temp_directory_path() / fmt::format("iblkit_ilfparts_{}_{}", name, ::getpid());
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

void write_text(const std::string& path, const std::string& s) { std::ofstream(path) << s; }

// A 16×16 sequence of `n` probes along x in the unit cube.
std::string tiny_sequence(const std::string& dir, int n, int size = 16) {
  SynthDesc sd;
  sd.out_dir = dir;
  sd.probes = n;
  sd.size = size;
  sd.supersample = 1;
  return write_synthetic_sequence(AnalyticField::three_spheres(), sd);
}

TEST(IlfSequence, BadManifests) {
  auto d = temp_dir("manifest");
  auto m = d + "/s.json";
  write_text(m, "{ not json");
  expect_error([&] { read_sequence(m); }, {"s.json", "not valid JSON"});
  write_text(m, R"({"format":"iblkit.sequence/2","probes":[]})");
  expect_error([&] { read_sequence(m); }, {"\"format\""});
  write_text(m, R"({"format":"iblkit.sequence/1","mapping":"fisheye","probes":[]})");
  expect_error([&] { read_sequence(m); }, {"\"mapping\"", "fisheye"});
  write_text(m, R"({"format":"iblkit.sequence/1","probes":[{"image":"a.exr","position":[0,0,0]},{"image":"b.exr"}]})");
  expect_error([&] { read_sequence(m); }, {"probe 1", "\"position\""});
  write_text(
      m,
      R"({"format":"iblkit.sequence/1","probes":[{"image":"a.exr","position":[0,0,0]},{"image":"b.exr","position":[0,"x",0]}]})");
  expect_error([&] { read_sequence(m); }, {"probe 1", "\"position\""});
  // Outside the volume and duplicates: errors, or skipped with skip_bad.
  write_text(m, R"({"format":"iblkit.sequence/1","volume":{"min":[0,0,0],"max":[1,1,1]},"probes":[
    {"image":"a.exr","position":[0.5,0.5,0.5]},{"image":"b.exr","position":[2,0.5,0.5]},
    {"image":"c.exr","position":[0.5,0.5,0.5]},{"image":"d.exr","position":[0.2,0.5,0.5]}]})");
  expect_error([&] { read_sequence(m); }, {"probe 1", "outside the volume", "skip_bad"});
  SequenceReadDesc rd;
  rd.skip_bad = true;
  SequenceReport rep;
  auto seq = read_sequence(m, rd, &rep);
  EXPECT_EQ(rep.skipped, 2);
  ASSERT_EQ(seq.probes.size(), 2u);
  EXPECT_EQ(fs::path(seq.probes[1].image).filename(), "d.exr");
  EXPECT_EQ(fs::path(seq.probes[1].image).parent_path(), fs::path(d));  // relative to the manifest
  write_text(
      m,
      R"({"format":"iblkit.sequence/1","probes":[{"image":"a.exr","position":[0,0,0]},{"image":"a.exr","position":[0,0,0]}]})");
  expect_error([&] { read_sequence(m); }, {"probe 1", "duplicates probe 0"});
}

TEST(IlfSequence, WriteReadRoundTripKeepsDepthAndScene) {
  auto d = temp_dir("roundtrip");
  Sequence seq;
  seq.mapping = sphere::MappingKind::LatLong;
  seq.dead_angle_deg = 2.5;
  seq.volume = {{-1, 0, -1}, {1, 2, 1}};
  seq.scene = "low-scene1";
  seq.probes = {{d + "/frames/a.exr", {0, 1, 0}, d + "/frames/a_depth.exr"}, {d + "/frames/b.exr", {0.5, 1, 0}, ""}};
  write_sequence(d + "/s.json", seq);
  // Paths inside the manifest's folder are written relative to it, read back absolute.
  std::ifstream in(d + "/s.json");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"frames/a_depth.exr\""), std::string::npos);
  EXPECT_NE(text.find("\"scene\": \"low-scene1\""), std::string::npos);
  const Sequence back = read_sequence(d + "/s.json");
  EXPECT_EQ(back.scene, "low-scene1");
  EXPECT_EQ(back.dead_angle_deg, 2.5);
  ASSERT_EQ(back.probes.size(), 2u);
  EXPECT_EQ(back.probes[0].image, fs::path(d + "/frames/a.exr").lexically_normal().string());
  EXPECT_EQ(back.probes[0].depth, fs::path(d + "/frames/a_depth.exr").lexically_normal().string());
  EXPECT_EQ(back.probes[1].depth, "");
  EXPECT_EQ(back.volume.max.y, 2);
  fs::remove_all(d);
}

TEST(IlfBuckets, SamplesAreTheFramesPixelsAndRunsAreReused) {
  auto d = temp_dir("buckets");
  auto seq = read_sequence(tiny_sequence(d, 5));
  for (int oct : {0, 4}) {
    BucketDesc bd;
    bd.dir = d + fmt::format("/b{}", oct);
    bd.octahedral = oct;
    bd.max_block_buckets = 3;
    bd.memory_bytes = size_t(64) << 20;
    BucketReport rep;
    auto st = BucketStore::sort(seq, bd, {}, &rep);
    EXPECT_FALSE(rep.reused);
    const auto& t = st.table();
    EXPECT_GT(t.blocks(), 1);
    double total_w = 0;
    for (double w : t.weight) total_w += w;
    constexpr double kDeadAngleTol = 0.02;  // 4π minus the 4.2° dead cone and partial rim pixels
    EXPECT_NEAR(total_w, 4 * kPi, kDeadAngleTol * 4 * kPi);
    std::vector<uint16_t> buf;
    std::vector<float> f(3);
    for (int p = 0; p < 5; ++p) {
      Image img = io::read_image(seq.probes[p].image);
      for (int k = 0; k < t.blocks(); ++k) {
        st.load_block(k, buf);
        for (int b = t.block_begin[k]; b < t.block_begin[k + 1]; ++b)
          for (int64_t s = t.bucket_begin[b]; s < t.bucket_begin[b + 1]; ++s) {
            halves_to_floats(st.samples(buf, k, b, p) + (s - t.bucket_begin[b]) * 3, f.data(), 3);
            int px = t.pixel[s] % t.width, py = t.pixel[s] / t.width;
            ASSERT_EQ(f[0], img.at(px, py, 0)) << "probe " << p << " slot " << s;  // frames are halves already
            ASSERT_EQ(f[2], img.at(px, py, 2));
          }
      }
    }
    BucketReport rep2;
    BucketStore::sort(seq, bd, {}, &rep2);
    EXPECT_TRUE(rep2.reused);
  }
}

TEST(IlfBuckets, BadFramesNameTheProbe) {
  auto d = temp_dir("badframes");
  auto seq = read_sequence(tiny_sequence(d, 6));
  io::write_image(seq.probes[2].image, Image(20, 20, 3, 1.0f), {true});  // wrong size
  io::write_image(seq.probes[4].image, Image(16, 16, 3, 0.0f), {true});  // all black
  fs::remove(seq.probes[5].image);                                       // missing
  BucketDesc bd;
  bd.dir = d + "/b";
  expect_error([&] { BucketStore::sort(seq, bd); }, {"probe ", "\"image\""});
  bd.skip_bad = true;
  BucketReport rep;
  auto st = BucketStore::sort(seq, bd, {}, &rep);
  EXPECT_EQ(rep.skipped, 3);
  EXPECT_EQ(st.valid(), (std::vector<uint8_t>{1, 1, 0, 1, 0, 0}));
  bool names_2 = false;
  for (auto& r : rep.reasons) names_2 |= r.find("probe 2") != std::string::npos && r.find("16x16") != std::string::npos;
  EXPECT_TRUE(names_2);
  // NaN pixels (only probes 0 and 1 now: frames are read in parallel, the first bad one found wins).
  seq.probes.resize(2);
  Image nan(16, 16, 3, 1.0f);
  nan.at(3, 4, 1) = std::nanf("");
  io::write_image(seq.probes[1].image, nan, {false});
  bd.skip_bad = false;
  expect_error([&] { BucketStore::sort(seq, bd); }, {"probe 1", "NaN"});
}

// Parallel rays of one direction from probes on a plane perpendicular to it: grid points within the
// kernel of the rays get exactly the rays' radiance (a constant); a two-valued field keeps its step.
TEST(IlfProject, ParallelRaysAndRepairs) {
  GridDesc grid{9, 9, 9, {{0, 0, 0}, {1, 1, 1}}};
  std::vector<Vec3> origins;
  std::vector<float> rad;
  for (int j = 0; j < 20; ++j)
    for (int i = 0; i < 20; ++i) {
      if (i >= 8 && i < 12 && j >= 8 && j < 12) continue;  // a hole of 0.2 m in the middle
      origins.push_back({i / 19.0, j / 19.0, 0.5});
      float v = i < 10 ? 2.0f : 4.0f;
      rad.insert(rad.end(), {v, v, v});
    }
  float dir[3] = {0, 0, 1};
  double w = 1.0;
  struct Ctx {
    const float* r;
  } ctx{rad.data()};
  BucketRays rays;
  rays.dirs = dir;
  rays.weights = &w;
  rays.n_dirs = 1;
  rays.origins = origins.data();
  rays.n_probes = int(origins.size());
  rays.ctx = &ctx;
  rays.radiance = [](const void* c, int p) { return static_cast<const Ctx*>(c)->r + 3 * p; };
  ProjectScratch sc;
  int64_t G = grid.count();
  std::vector<float> out(size_t(G) * 3);
  for (Repair r : {Repair::None, Repair::Mip, Repair::PullPush}) {
    ProjectDesc pd;
    pd.kernel_cells = 1.0;
    pd.repair = r;
    auto st = project_bucket(grid, rays, pd, out.data(), G, sc);
    EXPECT_EQ(st.rays, int64_t(origins.size()));
    EXPECT_GT(st.uncovered, 0) << "the hole must leave grid points without rays";
    constexpr double kTol = 1e-5;  // normalised weights of equal values
    for (int k = 0; k < 9; ++k) {
      // Column x = 0.125 (left of the step, outside the hole) holds 2 at every depth: rays are
      // projected through the whole volume in both directions.
      EXPECT_NEAR(out[grid.nx * 2 + 1 + size_t(k) * 81], 2.0, kTol);
      EXPECT_NEAR(out[grid.nx * 2 + 7 + size_t(k) * 81], 4.0, kTol);
    }
    float centre = out[size_t(4) * 81 + 4 * 9 + 4];  // (0.5, 0.5, 0.5): in the hole
    if (r == Repair::None)
      EXPECT_EQ(centre, 0.0f);
    else
      EXPECT_TRUE(centre > 2.0f - kTol && centre < 4.0f + kTol) << repair_name(r) << " " << centre;
  }
}

TEST(IlfRepair, MipFillsFromTheFinestLevelWithData) {
  GridDesc grid{8, 8, 8, {{0, 0, 0}, {1, 1, 1}}};
  int64_t G = grid.count();
  std::vector<float> v(size_t(G) * 3, 0.0f);
  std::vector<uint8_t> cov(size_t(G), 0);
  for (int64_t g = 0; g < G; ++g)
    if (g % 3 != 0) {
      cov[g] = 1;
      for (int c = 0; c < 3; ++c) v[c * G + g] = 5.0f;
    }
  EXPECT_EQ(repair_mip(grid, v.data(), G, cov.data()), (G + 2) / 3);
  constexpr double kTol = 1e-5;  // a constant stays constant
  for (int64_t g = 0; g < G; ++g) EXPECT_NEAR(v[2 * G + g], 5.0, kTol);
}

TEST(IlfSubsample, DropsRedundantNeighbours) {
  auto d = temp_dir("subsample");
  auto seq = read_sequence(tiny_sequence(d, 6));
  // Probes 1..4 become copies of probe 0 at nearly the same place: the middle ones are redundant.
  for (int p = 1; p < 5; ++p) {
    fs::copy_file(seq.probes[0].image, seq.probes[p].image, fs::copy_options::overwrite_existing);
    seq.probes[p].position = seq.probes[0].position + Vec3{0.01 * p, 0, 0};
  }
  SubsampleDesc sd;
  sd.threshold = 0.01;
  sd.max_distance = 0.05;
  SubsampleReport rep;
  auto keep = subsample(seq, sd, {}, &rep);
  EXPECT_EQ(keep, (std::vector<int>{0, 2, 4, 5}));  // 1 and 3 dropped; never two neighbours
  EXPECT_EQ(rep.dropped, 2);
  sd.max_distance = 0.005;  // too far apart now: nothing dropped
  EXPECT_EQ(subsample(seq, sd).size(), 6u);
}

}  // namespace
}  // namespace ibl::ilf
