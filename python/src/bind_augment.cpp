// augment/: compositing a virtual object into a photograph (differential rendering), as
// `iblkit composite`; the captured light (LocalRadiance) from files, an SH grid or fused probes.
#include "common.h"

#include <algorithm>
#include <cmath>
#include <span>

#include <fmt/format.h>

#include "iblkit/augment/composite.h"
#include "iblkit/augment/light.h"
#include "iblkit/augment/load.h"
#include "iblkit/augment/measure.h"
#include "iblkit/augment/run_composite.h"
#include "iblkit/capture/backplate.h"
#include "iblkit/core/check.h"
#include "iblkit/fusion/probe_set.h"
#include "iblkit/geometry/camera_io.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/render/shading.h"

namespace iblpy {

namespace {

namespace ag = ibl::augment;

// A photograph as composite() takes it: a uint8/uint16 array holds the camera's code values, linearised through
// `response` ("" = srgb, as the CLI's default for 8/16-bit files); a float array is linear light (response "" or
// "linear") or code values in [0, 1] through another curve.
ibl::capture::Backplate photo_input(py::handle photo, const std::string& response, const char* what) {
  ibl::capture::Backplate b;
  b.path = what;
  py::array a = py::array::ensure(photo);
  const int bits = a && a.dtype().kind() == 'u' ? (a.itemsize() == 1 ? 8 : a.itemsize() == 2 ? 16 : 0) : 0;
  if (a && a.dtype().kind() == 'u' && bits == 0)
    ibl::fail(ibl::ErrorKind::Value, "{}: unsigned integers of {} bytes; a photograph is uint8 or uint16", what,
              a.itemsize());
  if (bits == 0) {
    b.linear = to_checked_image(photo, what);
    b.response = ibl::capture::response_by_name(response.empty() ? "linear" : response);
    const int nc = b.linear.channels();
    if (b.response.kind != "linear")  // code values in [0, 1] through the curve
      for (size_t i = 0; i < b.linear.size(); ++i) {
        float& v = b.linear.data()[i];
        v = static_cast<float>(
            b.response.invert(std::clamp(static_cast<double>(v), 0.0, 1.0), std::min(2, int(i % nc))));
      }
    return b;
  }
  ibl::Image codes = to_image(py::array_t<float, py::array::forcecast>(a), what, 3);
  const float levels = bits == 8 ? 255.0f : 65535.0f;
  for (float& v : std::span(codes.data(), codes.size())) v /= levels;
  b.encoded = true;
  b.photo.codes = codes.with_channels(3);
  b.photo.bits = bits;
  b.response = ibl::capture::response_by_name(response.empty() ? "srgb" : response);
  b.linear = ibl::Image(b.photo.codes.width(), b.photo.codes.height(), 3);
  for (size_t i = 0; i < b.photo.codes.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c)
      b.linear.data()[3 * i + c] = static_cast<float>(b.response.invert(b.photo.codes.data()[3 * i + c], c));
  return b;
}

}  // namespace

void init_augment(py::module_& m) {
  py::class_<ag::LocalRadiance>(
      m, "LocalRadiance",
      "The captured light of a local scene as a composite uses it: a lat-long radiance map seen from `centre`.")
      .def(py::init([](py::handle map, py::handle centre, py::object depth) {
             ag::LocalRadiance l;
             ibl::Image img = to_checked_image(map, "LocalRadiance: map");
             ibl::sphere::Mapping mp = mapping_of("latlong", img.width(), img.height());
             l.map = ibl::sphere::EnvMap(std::move(img), mp);
             l.centre = to_vec3(centre, "LocalRadiance: centre");
             ibl::require_point("LocalRadiance: centre", l.centre);
             if (!depth.is_none()) {
               l.depth = to_image(depth, "LocalRadiance: depth");
               if (l.depth.width() != l.map.image.width() || l.depth.height() != l.map.image.height() ||
                   l.depth.channels() != 1)
                 throw py::value_error("LocalRadiance: depth must be (H, W) of the map's size");
             }
             l.source = "probe";
             return l;
           }),
           py::arg("map"), py::arg("centre"), py::arg("depth") = py::none(),
           "From a lat-long probe (H, 2H, 3) taken at `centre` and its optional (H, 2H) depth map (metres).")
      .def_static(
          "from_grid",
          [](const ibl::ilf::SHGrid& g, py::handle at, int size) {
            return ag::light_from_grid(g, to_vec3(at, "from_grid: at"), size);
          },
          py::arg("grid"), py::arg("at"), py::arg("size") = ag::LightInput{}.grid_map_size,
          "An SH grid's radiance at `at` as a 2·size × size map.")
      .def_static(
          "from_probes",
          [](const ibl::fusion::ProbeSet& s, py::handle at, int size) {
            ibl::Vec3 x = to_vec3(at, "from_probes: at");
            py::gil_scoped_release nogil;
            return ag::light_from_probes(s, x, size);
          },
          py::arg("probe_set"), py::arg("at"), py::arg("size") = ag::LightInput{}.fused_map_size,
          "A probe set fused at `at`.")
      .def("as_median_cut", &ag::as_median_cut, py::arg("count"),
           "The baseline of `count` median-cut lights, each in one texel.")
      .def_property_readonly(
          "map", [](const ag::LocalRadiance& l) { return to_array(l.map.image); }, "(H, 2H, 3) lat-long radiance.")
      .def_property_readonly("centre", [](const ag::LocalRadiance& l) { return vec3_tuple(l.centre); })
      .def_readonly("source", &ag::LocalRadiance::source);

  m.attr("LocalLight") = m.attr("LocalRadiance");  // the name before 2026-12 (kept for old scripts)

  py::class_<ag::CompositeResult>(m, "CompositeResult", "The composite and its layers (float32 arrays) and statistics.")
      .def_property_readonly(
          "composite", [](const ag::CompositeResult& r) { return to_array(r.composite); },
          "(H, W, 3) the photograph with the object.")
      .def_property_readonly(
          "mask", [](const ag::CompositeResult& r) { return to_array(r.mask, true); },
          "(H, W) share of each pixel the object covers.")
      .def_property_readonly(
          "difference", [](const ag::CompositeResult& r) { return to_array(r.difference); }, "composite − photograph.")
      .def_property_readonly(
          "albedo", [](const ag::CompositeResult& r) { return to_array(r.albedo); }, "Estimated proxy albedo.")
      .def_property_readonly("render_without", [](const ag::CompositeResult& r) { return to_array(r.render_without); })
      .def_property_readonly("render_with", [](const ag::CompositeResult& r) { return to_array(r.render_with); })
      .def_property_readonly("stats",
                             [](const ag::CompositeResult& r) {
                               py::dict d;
                               d["proxy_pixels"] = r.stats.proxy_pixels;
                               d["object_pixels"] = r.stats.object_pixels;
                               d["changed_pixels"] = r.stats.changed_pixels;
                               d["albedo_over_one"] = r.stats.albedo_over_one;
                               d["unlit"] = r.stats.unlit;
                               d["seconds"] = r.stats.seconds;
                               return d;
                             })
      .def_readonly("warnings", &ag::CompositeResult::warnings);

  static const ag::CompositeJob kJob;  // every default is the library's (and so the CLI's)
  static const ag::CompositeDesc& kDefaults = kJob.desc;
  m.def(
      "composite",
      [](py::handle photo, ibl::geometry::Camera camera, const ibl::geometry::TriMesh& object, py::object probes,
         py::object light, py::object proxy, py::object at_probe, const std::string& probe_depth, py::handle albedo,
         int median_cut, int light_samples, int object_samples, int bounce_samples, int triangle_samples,
         int pixel_samples, uint64_t seed, bool shadows, bool self_light, const std::string& backend, int gl_lights,
         double gl_threshold, int gl_visibility, const std::string& match, const std::string& reg,
         const std::string& response, py::object progress) {
        const ibl::capture::Backplate plate = photo_input(photo, response, "composite: photo");
        const ibl::Image& ph = plate.linear;
        camera.width = ph.width();
        camera.height = ph.height();
        ibl::geometry::validate_camera(camera, "composite: camera");
        ag::CompositeJob job;
        job.material = ibl::render::Material{to_vec3(albedo, "composite: albedo"), {0, 0, 0}};
        ibl::render::check_material(job.material, "composite: albedo");
        job.backend = ag::parse_backend(backend);
        job.median_cut = median_cut;
        if (match != "auto" && match != "off") throw py::value_error("composite: match must be \"auto\" or \"off\"");
        job.match = match == "off" ? ag::Match::Off : ag::Match::Auto;
        if (reg != "off" && reg != "check" && reg != "yaw")
          throw py::value_error("composite: register must be \"off\", \"check\" or \"yaw\"");
        job.reg = ag::parse_register(reg);
        ag::CompositeDesc& d = job.desc;
        d.light_samples = light_samples;
        d.object_samples = object_samples;
        d.bounce_samples = bounce_samples;
        d.triangle_samples = triangle_samples;
        d.pixel_samples = pixel_samples;
        d.seed = seed;
        d.shadows = shadows;
        d.self_light = self_light;
        d.gl.split.lights = gl_lights;
        d.gl.split.threshold = gl_threshold;
        d.gl.visibility_samples = gl_visibility;
        ag::CompositeScene scene;
        scene.object = object;
        if (!light.is_none() && py::isinstance<ag::LocalRadiance>(light)) {
          scene.light.light = light.cast<ag::LocalRadiance>();
          if (proxy.is_none())
            throw py::value_error("composite: a LocalRadiance needs proxy= (a TriMesh or a mesh file)");
          scene.light.proxy = py::isinstance<py::str>(proxy) ? ibl::geometry::read_mesh(proxy.cast<std::string>())
                                                             : proxy.cast<ibl::geometry::TriMesh>();
          ag::match_light(scene, ph, camera, job);
          if (median_cut > 0) scene.light.light = ag::as_median_cut(scene.light.light, median_cut);
        } else {  // files, as the CLI takes them
          if (!probes.is_none()) job.light.probes = py::str(probes);
          if (!light.is_none()) job.light.light = py::str(light);
          if (!proxy.is_none()) job.light.proxy = py::str(proxy);
          if (!at_probe.is_none()) job.light.at_probe = to_vec3(at_probe, "composite: at_probe");
          job.light.probe_depth = probe_depth;
          ibl::Vec3 lo, hi;
          object.bounds(&lo, &hi);
          py::gil_scoped_release nogil;
          scene.light = ag::load_light(job.light, lo, hi);
          ag::match_light(scene, ph, camera, job);
          if (median_cut > 0) scene.light.light = ag::as_median_cut(scene.light.light, median_cut);
        }
        Progress pr(progress);
        d.progress = pr.fn();
        ag::CompositeRun run;
        {
          py::gil_scoped_release nogil;
          run = ag::run_composite(ph, camera, job, scene);
        }
        pr.rethrow();
        run.result.warnings.insert(run.result.warnings.end(), run.notes.begin(), run.notes.end());
        return run.result;
      },
      py::arg("photo"), py::arg("camera"), py::arg("object"), py::arg("probes") = py::none(),
      py::arg("light") = py::none(), py::arg("proxy") = py::none(), py::arg("at_probe") = py::none(),
      py::arg("probe_depth") = kJob.light.probe_depth, py::arg("albedo") = vec3_tuple(kJob.material.albedo),
      py::arg("median_cut") = kJob.median_cut, py::arg("light_samples") = kDefaults.light_samples,
      py::arg("object_samples") = kDefaults.object_samples, py::arg("bounce_samples") = kDefaults.bounce_samples,
      py::arg("triangle_samples") = kDefaults.triangle_samples, py::arg("pixel_samples") = kDefaults.pixel_samples,
      py::arg("seed") = kDefaults.seed, py::arg("shadows") = kDefaults.shadows,
      py::arg("self_light") = kDefaults.self_light, py::arg("backend") = std::string(ag::backend_name(kJob.backend)),
      py::arg("gl_lights") = kDefaults.gl.split.lights, py::arg("gl_threshold") = kDefaults.gl.split.threshold,
      py::arg("gl_visibility") = kDefaults.gl.visibility_samples,
      py::arg("match") = std::string(kJob.match == ag::Match::Auto ? "auto" : "off"), py::arg("register") = "off",
      py::arg("response") = "", py::arg("progress") = py::none(),
      R"doc(Composites `object` (a TriMesh, e.g. TriMesh.object(at=…)) into the photograph (H, W, 3) seen by
`camera` (its size becomes the photograph's), as `iblkit composite` (Debevec 1998): a CompositeResult
with the composite, mask, difference, albedo and render layers.

The captured light, as the CLI takes it: probes= an iblkit.probes/1 manifest; or light= an SH grid
(.shgrid) or a probe image file (with at_probe=) and proxy= a mesh file; or light= a LocalRadiance with
proxy= a TriMesh or mesh file. median_cut > 0: the N-light baseline. Sampling: light_samples,
object_samples, bounce_samples (0: no bounce), triangle_samples, pixel_samples, seed; shadows=False
pastes the object without its shadow; self_light=False leaves out the object's light on itself (CPU). backend= "cpu" (the ray-traced reference), "gl" (OpenGL: shadow
maps and the soft sphere term; gl_lights, gl_threshold, gl_visibility as --gl-lights, --gl-threshold,
--gl-visibility) or "auto". match="auto" puts the light in the photograph's units (the gains from the
proxy points both see; result.warnings says them), "off" keeps it as captured. register="yaw" first turns the
light about +Y to agree best with the photograph on those points ("check": measured and said in result.warnings
only; docs/augment.md "Registration"). A uint8/uint16 photo holds the
camera's codes, made linear through response= ("" = "srgb", "linear", "camera" or an iblkit.response/1 file);
result.composite is linear: encode_photo(result.composite, photo, response) writes it back into the photo's codes.
Every default is the library's (augment::CompositeJob). Releases the GIL; progress(stage, fraction).)doc");

  m.def(
      "encode_photo",
      [](py::handle composite, py::handle photo, const std::string& response) {
        const ibl::capture::Backplate plate = photo_input(photo, response, "encode_photo: photo");
        if (!plate.encoded)
          ibl::fail(ibl::ErrorKind::Value, "encode_photo: photo must be the uint8/uint16 array composite() took");
        const ibl::Image codes = ibl::capture::encode_like(plate, to_image(composite, "encode_photo: composite", 3));
        const double levels = plate.photo.bits == 8 ? 255.0 : 65535.0;
        const auto H = static_cast<py::ssize_t>(codes.height()), W = static_cast<py::ssize_t>(codes.width());
        if (plate.photo.bits == 8) {
          py::array_t<uint8_t> out({H, W, py::ssize_t(3)});
          auto* p = out.mutable_data();
          for (size_t i = 0; i < codes.size(); ++i) p[i] = static_cast<uint8_t>(std::lround(codes.data()[i] * levels));
          return py::object(out);
        }
        py::array_t<uint16_t> out({H, W, py::ssize_t(3)});
        auto* p = out.mutable_data();
        for (size_t i = 0; i < codes.size(); ++i) p[i] = static_cast<uint16_t>(std::lround(codes.data()[i] * levels));
        return py::object(out);
      },
      py::arg("composite"), py::arg("photo"), py::arg("response") = "",
      "The linear composite back into the uint8/uint16 photo's codes through `response` (as composite() took it):\n"
      "pixels the composite left exactly as they were keep their codes, the others are encoded and rounded.");

  m.def(
      "measure_composite",
      [](py::handle photo, py::handle composite, py::handle truth, py::handle mask, double threshold) {
        auto e = ag::measure(to_image(photo, "photo", 3), to_image(composite, "composite", 3),
                             to_image(truth, "truth", 3), to_image(mask, "mask", 1), threshold);
        py::dict d;
        d["object"] = e.object;
        d["shadow"] = e.shadow;
        d["unchanged"] = e.unchanged;
        d["object_pixels"] = e.object_pixels;
        d["shadow_pixels"] = e.shadow_pixels;
        d["brightened_pixels"] = e.brightened_pixels;
        d["unchanged_pixels"] = e.unchanged_pixels;
        d["shadow_signal"] = e.shadow_signal;
        return d;
      },
      py::arg("photo"), py::arg("composite"), py::arg("truth"), py::arg("mask"), py::arg("threshold") = 0.02,
      "A composite's error against a true photograph of the object (docs/augment.md): object, shadow, unchanged.");
}

}  // namespace iblpy
