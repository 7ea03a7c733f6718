// lab/ (submodule iblkit.lab): analytic scenes, synthetic captures and sequences, photographs and
// exact ground truth, with the CLI's defaults (`iblkit lab capture | truth | photograph`).
#include "common.h"

#include <fmt/format.h>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/camera_io.h"
#include "iblkit/lab/capture.h"
#include "iblkit/lab/scene_io.h"
#include "iblkit/lab/sequence.h"
#include "iblkit/lab/truth.h"
#include "iblkit/lab/view.h"

namespace iblpy {

namespace {

using ibl::lab::Scene;

// The probe frame whose +Z is `look` in the world, +Y up where possible (as `lab capture --look`).
ibl::Mat3 look_rotation(ibl::Vec3 look) {
  ibl::Vec3 z = ibl::require_direction("look", look);
  ibl::Vec3 up = std::abs(z.y) > 0.999 ? ibl::Vec3{0, 0, -z.y} : ibl::Vec3{0, 1, 0};
  ibl::Vec3 x = ibl::normalize(ibl::cross(up, z)), y = ibl::cross(z, x);
  return ibl::Mat3::rows(x, y, z).transposed();
}

ibl::lab::CaptureDesc capture_desc(const Scene& scene, const std::string& mapping, int size, int samples,
                                   double dead_angle, py::handle look, const std::string& camera, bool depth,
                                   int bounces, int seed) {
  ibl::lab::CaptureDesc d;
  d.render = scene.render;
  if (bounces >= 0) d.render.bounces = bounces;
  if (seed > 0) d.render.seed = static_cast<uint64_t>(seed);
  d.mapping = ibl::sphere::parse_mapping(mapping, "mapping");
  d.size = size;
  d.samples = samples;
  d.dead_angle_deg = dead_angle;
  d.rotation = look_rotation(to_vec3(look, "look"));
  if (camera != "ideal" && camera != "ball")
    ibl::fail(ibl::ErrorKind::Value, "camera: expected ideal or ball, got {}", camera);
  d.camera = camera == "ball" ? ibl::lab::Camera::MirrorBall : ibl::lab::Camera::Ideal;
  if (d.camera == ibl::lab::Camera::MirrorBall) d.mapping = ibl::sphere::MappingKind::MirrorBall;
  d.depth = depth;
  if (size < 1 || size > 8192) ibl::fail(ibl::ErrorKind::Value, "size must be in 1..8192 (got {})", size);
  if (samples < 1 || samples > 64) ibl::fail(ibl::ErrorKind::Value, "samples must be in 1..64 (got {})", samples);
  return d;
}

}  // namespace

// Also used by bind_nearfield.cpp.
const Scene& scene_arg(py::handle obj) { return obj.cast<const Scene&>(); }

void init_lab(py::module_& top) {
  py::module_ m = top.def_submodule(
      "lab", "The test bench: analytic scenes, synthetic captures, photographs and exact ground truth.");

  py::class_<Scene>(m, "Scene",
                    "A lab scene (iblkit.scene/1), built and ready to ray trace (the library's lab::Scene).")
      .def_static(
          "load",
          [](const std::string& name_or_path) {
            py::gil_scoped_release nogil;
            return ibl::lab::load_scene(name_or_path);
          },
          py::arg("name_or_path"),
          "Loads a scene file, or a built-in scene: low-scene1, low-scene2, t-corridor, crypt.")
      .def_readonly("name", &Scene::name)
      .def_readonly("description", &Scene::description)
      .def_readonly("source", &Scene::source, "The file it came from.")
      .def_property_readonly(
          "volume", [](const Scene& s) { return py::make_tuple(vec3_tuple(s.volume_min), vec3_tuple(s.volume_max)); },
          "(min, max) of the capture volume.")
      .def_property_readonly("surface_count", [](const Scene& s) { return s.surfaces.size(); })
      .def("proxy_mesh", &Scene::proxy_mesh, "The proxy mesh (the proxy file, or every surface marked proxy).")
      .def("__repr__",
           [](const Scene& s) { return fmt::format("lab.Scene('{}', {} surfaces)", s.name, s.surfaces.size()); });

  py::class_<ibl::lab::Truth>(m, "Truth",
                              "Exact answers at a point: the radiance map, its SH and the irradiance at normals.")
      .def_property_readonly(
          "radiance", [](const ibl::lab::Truth& t) { return to_array(t.radiance.image); },
          "(size, 2·size, 3) lat-long radiance.")
      .def_readonly("sh", &ibl::lab::Truth::sh, "SH projection of the radiance map (SHCoeffs).")
      .def_property_readonly("normals", [](const ibl::lab::Truth& t) { return vec3_array(t.normals); })
      .def_property_readonly(
          "irradiance", [](const ibl::lab::Truth& t) { return vec3_array(t.irradiance); }, "(N, 3) E(n), W/m².");

  m.def(
      "capture",
      [](const Scene& scene, py::handle position, const std::string& mapping, int size, int samples, double dead_angle,
         py::handle look, const std::string& camera, bool depth, int bounces, int seed, int probe_index,
         py::object progress) -> py::object {
        ibl::Vec3 p = to_vec3(position, "capture: position");
        ibl::require_point("capture position", p);
        auto d = capture_desc(scene, mapping, size, samples, dead_angle, look, camera, depth, bounces, seed);
        Progress pr(progress);
        ibl::lab::Capture c;
        {
          py::gil_scoped_release nogil;
          c = ibl::lab::capture_probe(scene, p, d, static_cast<uint64_t>(probe_index), pr.fn());
        }
        pr.rethrow();
        if (depth) return py::make_tuple(to_array(std::move(c.radiance)), to_array(std::move(c.depth), true));
        return to_array(std::move(c.radiance));
      },
      py::arg("scene"), py::arg("position"), py::arg("mapping") = "latlong", py::arg("size") = 64,
      py::arg("samples") = 1, py::arg("dead_angle") = 0.0, py::arg("look") = py::make_tuple(0, 0, 1),
      py::arg("camera") = "ideal", py::arg("depth") = false, py::arg("bounces") = -1, py::arg("seed") = 0,
      py::arg("probe_index") = 0, py::arg("progress") = py::none(),
      R"doc(A synthetic probe of the scene at `position`, as one probe of `iblkit lab capture`: an (H, W, 3)
float32 radiance array, or (radiance, depth (H, W)) with depth=True. size: lat-long height, cube face
edge or disc diameter; samples: n×n sub-pixel rays; look: the world direction of the probe's +Z;
camera: "ideal" or "ball" (a physical mirror ball); bounces/seed: override the scene's (−1/0 keep
them); probe_index keys the random streams (probe k of a sequence).)doc");

  m.def(
      "write_sequence",
      [](const Scene& scene, py::handle positions, const std::string& out_dir, const std::string& mapping, int size,
         int samples, double dead_angle, py::handle look, const std::string& camera, bool depth, int bounces, int seed,
         const std::string& format, bool half, bool fusion, py::object progress) {
        auto pos = to_vec3s(positions, "write_sequence: positions");
        ibl::lab::SequenceDesc d;
        d.capture = capture_desc(scene, mapping, size, samples, dead_angle, look, camera, depth, bounces, seed);
        d.out_dir = out_dir;
        d.frame_ext = "." + format;
        d.half = half;
        Progress pr(progress);
        ibl::lab::SequenceResult r;
        {
          py::gil_scoped_release nogil;
          r = fusion ? ibl::lab::write_probe_set(scene, pos, d, pr.fn())
                     : ibl::lab::write_sequence(scene, pos, d, pr.fn());
        }
        pr.rethrow();
        return r.manifest;
      },
      py::arg("scene"), py::arg("positions"), py::arg("out_dir"), py::arg("mapping") = "latlong", py::arg("size") = 64,
      py::arg("samples") = 1, py::arg("dead_angle") = 0.0, py::arg("look") = py::make_tuple(0, 0, 1),
      py::arg("camera") = "ideal", py::arg("depth") = false, py::arg("bounces") = -1, py::arg("seed") = 0,
      py::arg("format") = "exr", py::arg("half") = false, py::arg("fusion") = false, py::arg("progress") = py::none(),
      R"doc(Captures probes at (N, 3) positions into out_dir, as `iblkit lab capture`: frames and an
iblkit.sequence/1 manifest (for ilf.build), or with fusion=True an iblkit.probes/1 set with depth maps
and the proxy (for load_probe_set). Returns the manifest's path.)doc");

  m.def(
      "ground_truth",
      [](const Scene& scene, py::handle position, int size, int samples, int area_samples, int bands,
         py::object normals, int seed, py::object progress) {
        ibl::Vec3 p = to_vec3(position, "ground_truth: position");
        ibl::require_point("ground truth position", p);
        ibl::lab::TruthDesc d;
        d.size = size;
        d.samples = samples;
        d.area_samples = area_samples;
        d.bands = bands;
        d.seed = static_cast<uint64_t>(seed);
        if (normals.is_none())
          d.normals = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
        else
          d.normals = to_vec3s(normals, "ground_truth: normals");
        for (auto& n : d.normals) n = ibl::require_direction("ground_truth: normal", n);
        Progress pr(progress);
        ibl::lab::Truth t;
        {
          py::gil_scoped_release nogil;
          t = ibl::lab::ground_truth(scene, p, d, pr.fn());
        }
        pr.rethrow();
        return t;
      },
      py::arg("scene"), py::arg("position"), py::arg("size") = ibl::lab::TruthDesc{}.size,
      py::arg("samples") = ibl::lab::TruthDesc{}.samples, py::arg("area_samples") = ibl::lab::TruthDesc{}.area_samples,
      py::arg("bands") = ibl::lab::TruthDesc{}.bands, py::arg("normals") = py::none(),
      py::arg("seed") = static_cast<int>(ibl::lab::TruthDesc{}.seed), py::arg("progress") = py::none(),
      "The exact answers at a point, as `iblkit lab truth` (default normals: ±X, ±Y, ±Z): a Truth.");

  m.def(
      "photograph",
      [](const Scene& scene, const ibl::geometry::Camera& camera, py::object object, py::handle albedo, int samples,
         int bounces, int area_samples, int env_samples, int seed, bool surface, py::object progress) -> py::object {
        ibl::geometry::validate_camera(camera, "photograph: camera");
        const Scene* use = &scene;
        Scene with_object;
        if (!object.is_none()) {  // the object goes into a fresh, unbuilt copy of the scene (as the CLI does)
          if (scene.source.empty())
            ibl::fail(ibl::ErrorKind::Value, "photograph: an object needs a scene loaded from a file");
          ibl::Vec3 a = to_vec3(albedo, "photograph: albedo");
          for (int c = 0; c < 3; ++c)
            if (!(a[c] >= 0 && a[c] <= 1)) ibl::fail(ibl::ErrorKind::Value, "photograph: albedo must lie in [0, 1]");
          with_object = ibl::lab::load_scene(scene.source, false);
          ibl::lab::add_object(with_object, "object", object.cast<ibl::geometry::TriMesh>(), a);
          with_object.build();
          use = &with_object;
        }
        const Scene& sc = *use;
        ibl::lab::ViewDesc vd;
        vd.width = camera.width;
        vd.height = camera.height;
        vd.samples = samples;
        vd.render = sc.render;
        vd.render.bounces = bounces;
        if (area_samples > 0) vd.render.area_samples = area_samples;
        if (env_samples > 0) vd.render.env_samples = env_samples;
        vd.render.seed = static_cast<uint64_t>(seed);
        Progress pr(progress);
        ibl::lab::View v;
        {
          py::gil_scoped_release nogil;
          ibl::geometry::Camera cam = camera;
          v = ibl::lab::photograph(
              sc,
              [&](double px, double py, ibl::Vec3* o, ibl::Vec3* d) {
                *o = cam.eye;
                *d = cam.ray_direction(px, py);
              },
              vd, pr.fn());
        }
        pr.rethrow();
        if (surface) return py::make_tuple(to_array(std::move(v.radiance)), to_array(std::move(v.surface), true));
        return to_array(std::move(v.radiance));
      },
      py::arg("scene"), py::arg("camera"), py::arg("object") = py::none(),
      py::arg("albedo") = py::make_tuple(0.7, 0.7, 0.7), py::arg("samples") = 4, py::arg("bounces") = 1,
      py::arg("area_samples") = 0, py::arg("env_samples") = 0, py::arg("seed") = 1, py::arg("surface") = false,
      py::arg("progress") = py::none(),
      R"doc(A path-traced pinhole photograph of the scene, as `iblkit lab photograph`: (H, W, 3) float32
radiance (with surface=True also the (H, W) index of the surface each pixel centre sees, −1 none).
object: a TriMesh (e.g. TriMesh.object(at=…)) put into the scene with Lambertian `albedo`.)doc");

  m.def(
      "grid_positions",
      [](py::handle lo, py::handle hi, int nx, int ny, int nz) {
        return vec3_array(ibl::lab::grid_positions(to_vec3(lo, "lo"), to_vec3(hi, "hi"), nx, ny, nz));
      },
      py::arg("lo"), py::arg("hi"), py::arg("nx"), py::arg("ny"), py::arg("nz"),
      "nx·ny·nz points spanning [lo, hi], x fastest: (N, 3).");
  m.def(
      "random_positions",
      [](py::handle lo, py::handle hi, int count, int seed) {
        if (count < 1 || count > 10000000)
          ibl::fail(ibl::ErrorKind::Value, "random_positions: count must be in 1..1e7 (got {})", count);
        return vec3_array(
            ibl::lab::random_positions(to_vec3(lo, "lo"), to_vec3(hi, "hi"), count, static_cast<uint64_t>(seed)));
      },
      py::arg("lo"), py::arg("hi"), py::arg("count"), py::arg("seed") = 1,
      "`count` uniform random points in [lo, hi]: (N, 3).");
}

}  // namespace iblpy
