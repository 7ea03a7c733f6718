// GPU time per frame of the real-time renderer (issue 8 targets, on the device machine's H100):
// SH-grid diffuse ≤ 0.5 ms and glossy ≤ 1 ms at 1024×768 for a 100k-triangle object; directional
// lights with shadow maps; the 9×7 near-field dataset's textured spotlights with shadows in a room
// (≤ 4 ms). Built as the lean target iblkit_glbench (no OpenImageIO/Embree/…), so it
// can be carried to a GPU machine with a handful of shared libraries. Prints one JSON object.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "iblkit/augment/gl/compositor.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/nearfield/spotlight.h"
#include "iblkit/render/gl/context.h"
#include "iblkit/render/gl/renderer.h"

using namespace ibl;
using namespace ibl::render;

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

ilf::SHGrid make_grid(int n, int bands) {
  ilf::GridDesc gd;
  gd.nx = gd.ny = gd.nz = n;
  gd.volume = {{-0.6, -0.6, -0.6}, {0.6, 0.6, 0.6}};
  ilf::SHGrid g(gd, bands);
  const int K = bands * bands;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        for (int k = 0; k < K; ++k)
          for (int c = 0; c < 3; ++c) {
            size_t i = ((((static_cast<size_t>(z) * n + y) * n + x) * K + k) * 3 + c);
            g.data()[i] = static_cast<float>((k == 0 ? 2.0 : 0.3 / (1 + k)) *
                                             (1 + 0.3 * std::sin(0.3 * x + 0.2 * y - 0.1 * z + c)));
          }
  return g;
}

// A box room (inward-facing walls) of w × h × l metres with its floor at y = 0, and four pillars:
// a stand-in for the crypt (examples/crypt.obj needs assimp, which the lean target leaves out).
geometry::TriMesh make_room(double w, double h, double l) {
  geometry::TriMesh room;
  auto quad = [&](Vec3 a, Vec3 b, Vec3 c, Vec3 d) {  // counter-clockwise seen from the side it faces
    geometry::TriMesh q;
    q.positions = {a, b, c, d};
    q.triangles = {{0, 1, 2}, {0, 2, 3}};
    q.compute_normals();
    room.append(q);
  };
  auto box = [&](Vec3 lo, Vec3 hi, bool inward) {
    Vec3 c[8];
    for (int i = 0; i < 8; ++i) c[i] = {i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z};
    int f[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};  // outward
    for (auto& q : f) inward ? quad(c[q[3]], c[q[2]], c[q[1]], c[q[0]]) : quad(c[q[0]], c[q[1]], c[q[2]], c[q[3]]);
  };
  box({-w / 2, 0, -l / 2}, {w / 2, h, l / 2}, true);
  for (double x : {-1.5, 1.5})
    for (double z : {-2.0, 2.0}) box({x - 0.25, 0, z - 0.25}, {x + 0.25, h, z + 0.25}, false);
  return room;
}

// The crypt of examples/crypt.obj (522 triangles, like Granier et al.'s 500): positions and
// triangles only, read here because the lean target has no assimp. Empty when the file is missing.
geometry::TriMesh read_obj(const std::string& path) {
  geometry::TriMesh m;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v") {
      float x, y, z;
      ls >> x >> y >> z;
      m.positions.push_back({x, y, z});
    } else if (tag == "f") {
      std::vector<uint32_t> f;
      std::string v;
      while (ls >> v) {
        const long i = std::stol(v.substr(0, v.find('/')));
        if (i < 1 || static_cast<size_t>(i) > m.positions.size())
          throw std::runtime_error(
              path + ": vertex index " + std::to_string(i) +
              " is out of range (this reader takes positive indices of vertices listed before the face)");
        f.push_back(static_cast<uint32_t>(i - 1));
      }
      for (size_t k = 2; k < f.size(); ++k) m.triangles.push_back({f[0], f[k - 1], f[k]});
    }
  }
  if (!m.triangles.empty()) m.compute_normals();
  return m;
}

// 9×7 textured spotlights like a measured luminaire's terms (5 mm apart, texture² with mips), at
// `at` aimed along `forward`.
std::vector<nearfield::TexturedSpotlight> make_spotlights(Vec3 at, Vec3 forward, int texture) {
  Image tex(texture, texture, 3);
  const double c = (texture - 1) / 2.0;
  for (int y = 0; y < texture; ++y)
    for (int x = 0; x < texture; ++x) {
      double r = std::hypot(x - c, y - c) / (texture / 2.0);
      tex.set_rgb(x, y, Vec3{1, 0.9, 0.7} * (2000.0 * std::exp(-8 * (r - 0.5) * (r - 0.5)) * (r < 1 ? 1 : 0)));
    }
  auto mips = std::make_shared<const std::vector<Image>>(nearfield::build_mips(tex));
  std::vector<nearfield::TexturedSpotlight> out;
  const Frame fr = Frame::from_normal(normalize(forward));
  for (int j = 0; j < 7; ++j)
    for (int i = 0; i < 9; ++i) {
      nearfield::TexturedSpotlight sp;
      sp.position = at + fr.t * (0.005 * (i - 4)) + fr.b * (0.005 * (j - 3));
      sp.frame = fr;
      sp.plane_distance = 0.5;
      sp.tex_min = {-0.3, -0.3};
      sp.tex_max = {0.3, 0.3};
      sp.mips = mips;
      sp.support_area = 0.005 * 0.005;
      sp.support_width = 0.02;
      out.push_back(sp);
    }
  return out;
}

// One entry of the JSON object: the median GPU time and the wall time per frame.
void report(const char* path, const std::string& name, const gl::GpuTiming& t) {
  std::printf(",\n \"%s_%s_ms\": %.4f, \"%s_%s_wall_ms\": %.2f", path, name.c_str(), median(t.frame_ms), path,
              name.c_str(), t.wall_ms_per_frame);
}

}  // namespace

int main(int argc, char** argv) {
  int frames = argc > 1 ? std::atoi(argv[1]) : 50;
  int tris = argc > 2 ? std::atoi(argv[2]) : 100000;
  int width = argc > 3 ? std::atoi(argv[3]) : 1024, height = argc > 4 ? std::atoi(argv[4]) : 768;
  const std::string crypt_path = argc > 5 ? argv[5] : "examples/crypt.obj";
  try {
    gl::Context ctx;
    geometry::TriMesh blob = geometry::make_blob(tris, 0.8);
    geometry::TriMesh crypt = read_obj(crypt_path);
    if (crypt.triangles.empty())
      std::fprintf(stderr, "iblkit_glbench: no %s, skipping the crypt case\n", crypt_path.c_str());
    std::printf("{\"renderer\": \"%s\", \"triangles\": %zu, \"size\": \"%dx%d\", \"frames\": %d",
                ctx.renderer().c_str(), blob.triangle_count(), width, height, frames);
    // A sixth argument "composite" runs the compositor's case alone (llvmpipe takes minutes for the others).
    const bool composite_only = argc > 6 && std::string(argv[6]) == "composite";
    for (bool deferred : {false, true}) {
      if (composite_only) break;
      gl::Renderer r({deferred});
      FrameDesc d;
      d.camera.eye = {0, 0.4, 1.6};
      d.camera.target = {0, 0, 0};
      d.camera.width = width;
      d.camera.height = height;
      d.objects.push_back({&blob, Material{{0.7, 0.7, 0.7}, {0, 0, 0}, 1}});
      const char* path = deferred ? "deferred" : "forward";
      auto run = [&](const char* name) {
        gl::GpuTiming t;
        r.render(d, frames, &t);
        report(path, name, t);
      };
      for (int n : {8, 16, 32}) {
        d.lighting.grid = make_grid(n, 5);
        d.objects[0].material = Material{{0.7, 0.7, 0.7}, {0, 0, 0}, 1};
        run(("shgrid" + std::to_string(n) + "_b5_diffuse").c_str());
      }
      d.objects[0].material = Material{{0.6, 0.6, 0.6}, {0.3, 0.3, 0.3}, 30};
      run("shgrid32_b5_glossy_s30");
      {
        // Löw et al.'s suggested variant: the SH basis from a precomputed table (64² cube faces)
        // instead of per-fragment polynomials.
        gl::Renderer table({.deferred = deferred, .sh_table_size = 64});
        for (bool glossy : {false, true}) {
          d.objects[0].material =
              glossy ? Material{{0.6, 0.6, 0.6}, {0.3, 0.3, 0.3}, 30} : Material{{0.7, 0.7, 0.7}, {0, 0, 0}, 1};
          gl::GpuTiming t;
          table.render(d, frames, &t);
          const char* name = glossy ? "shgrid32_b5_glossy_s30_table64" : "shgrid32_b5_diffuse_table64";
          report(path, name, t);
        }
      }
      d.lighting.grid.reset();
      for (int i = 0; i < 256; ++i) {
        double th = std::acos(1 - (i + 0.5) / 256.0), ph = 2.39996 * i;
        d.lighting.lights.push_back(
            {{std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)}, {0.02, 0.02, 0.02}, i < 16});
      }
      run("lights256_16_shadowed");
      d.lighting.lights.resize(16);
      run("lights16_all_shadowed");
      for (auto& l : d.lighting.lights) l.shadow = false;
      run("lights16_no_shadows");
      // Granier et al.'s case: a 9×7 near-field dataset, every term a textured spotlight of 256²
      // (theirs: 300²) with its own 512² shadow map, lighting the crypt (examples/crypt.obj, 522
      // triangles; theirs: 500) — and, harder, a room with pillars and a 50k-triangle object.
      d.lighting.lights.clear();
      d.spot_shadow_map_size = 512;
      d.objects.clear();
      if (!crypt.triangles.empty()) {
        d.lighting.spotlights =
            make_spotlights({-0.55, 0.45, -0.75}, Vec3{-1.3, 0.25, -1.6} - Vec3{-0.55, 0.45, -0.75}, 256);
        d.objects = {{&crypt, Material{{0.62, 0.58, 0.5}, {0, 0, 0}, 1}}};
        d.camera.eye = {1.5, 1.7, 3.2};
        d.camera.target = {-0.8, 0.6, -1.2};
        run("nearfield_9x7_crypt");
        // What the shadows cost: smaller maps, and none.
        d.spot_shadow_map_size = 256;
        run("nearfield_9x7_crypt_shadow256");
        d.spot_shadow_map_size = 512;
        d.spot_shadow_share = 0.011;  // 13 maps for the 63 terms 5 mm apart
        run("nearfield_9x7_crypt_share11mm");
        d.spot_shadow_share = 0.021;  // 4 maps
        run("nearfield_9x7_crypt_share21mm");
        d.spot_shadow_share = 0;
        for (auto& sp : d.lighting.spotlights) sp.shadow = false;
        run("nearfield_9x7_crypt_no_shadows");
        for (auto& sp : d.lighting.spotlights) sp.shadow = true;
        if (deferred) {
          gl::Renderer per_pass({.deferred = deferred, .layered_shadows = false});
          gl::GpuTiming t;
          per_pass.render(d, frames, &t);
          report(path, "nearfield_9x7_crypt_shadow_pass_per_light", t);
        }
      }
      d.lighting.spotlights = make_spotlights({-1.0, 2.2, 2.5}, {0.3, -0.6, -1}, 128);
      geometry::TriMesh room = make_room(6, 4, 8);
      geometry::TriMesh small = blob;
      small.transform(0.5, {0, 0.2, 0});
      d.objects = {{&small, Material{{0.7, 0.7, 0.7}, {0.2, 0.2, 0.2}, 20}},
                   {&room, Material{{0.6, 0.6, 0.6}, {0, 0, 0}, 1}}};
      d.camera.eye = {0.5, 1.6, 3.5};
      d.camera.target = {0, 0.5, 0};
      run("nearfield_9x7_shadowed_room");
      d.lighting.spotlights.clear();
      d.objects.resize(1);
      d.objects[0] = {&blob, Material{{0.7, 0.7, 0.7}, {0, 0, 0}, 1}};
      d.camera.eye = {0, 0.4, 1.6};
      d.camera.target = {0, 0, 0};
    }
    {
      // Issue 14: the compositor (augment/gl/compositor.h) at width × height: the blob (tris, 0.4 m) over a
      // room proxy (make_room), 16 hard lights each with its object and proxy shadow maps (512², 3×3 PCF;
      // 12 points on the ceiling, 4 distant), the soft sphere term, 4× MSAA; the object moves every frame.
      geometry::TriMesh room = make_room(6, 4, 8);
      geometry::Camera cam;
      cam.eye = {0.5, 1.6, 3.5};
      cam.target = {0, 0.5, 0};
      cam.width = width;
      cam.height = height;
      augment::SplitLight L;
      L.centre = {0, 0.5, 0};
      L.hard.origin = L.centre;
      L.soft = Image(128, 64, 3, 0.2f);
      L.soft_irradiance = Image(64, 32, 3, static_cast<float>(0.2 * kPi));
      for (int i = 0; i < 16; ++i) {
        lights::Light h;
        h.irradiance = {0.3, 0.3, 0.3};
        if (i < 12) {
          h.position = Vec3{-2.5 + (i % 4) * 5.0 / 3, 4.0, -3.0 + (i / 4) * 3.0};
          h.direction = normalize(*h.position - L.centre);
        } else {
          h.direction = normalize(Vec3{std::cos(i * 1.3), 2.0, std::sin(i * 1.3)});
        }
        L.hard.lights.push_back(h);
      }
      augment::gl::Compositor comp(Image(width, height, 3, 0.3f), cam, room, L, Image(width, height, 3, 0.5f));
      geometry::TriMesh object = blob;
      object.transform(0.5, {0, 0.5, 0});
      comp.set_object(object, {0.7, 0.7, 0.7});
      std::vector<double> gpu;
      double wall = 0;
      for (int f = 0; f < frames; ++f) {
        augment::gl::GlFrameTiming t;
        comp.draw({0.2 * std::sin(0.1 * f), 0, 0}, false, &t);
        gpu.push_back(t.gpu_ms);
        wall += t.wall_ms;
      }
      std::printf(",\n \"composite_16_lights_ms\": %.4f, \"composite_16_lights_wall_ms\": %.2f", median(gpu),
                  wall / std::max(1, frames));
    }
    std::printf("}\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "iblkit_glbench: %s\n", e.what());
    return 1;
  }
  return 0;
}
