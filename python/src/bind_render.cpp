// render/: the CPU reference renderer over any of the library's lightings, with the defaults of
// `iblkit render --backend cpu` (the object on a floor, the camera looking at it).
#include "common.h"

#include <fmt/format.h>

#include "iblkit/core/check.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/camera_io.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/render/cpu_renderer.h"
#include "iblkit/render/lighting_io.h"
#include "iblkit/render/objects.h"
#include "iblkit/sh/project.h"

namespace iblpy {

ibl::sh::Coeffs coeffs_arg(py::handle obj, const char* what);  // bind_sh.cpp

namespace {

namespace rd = ibl::render;

// The lighting of a render from one Python value (a path, SHCoeffs, SHGrid, LightSet or a probe image).
void add_lighting(py::handle light, int bands, int shadows, const std::string& mapping, rd::Lighting* L) {
  if (py::isinstance<py::str>(light)) {
    rd::LightingReadDesc d;
    d.bands = bands;
    d.shadows = shadows;
    std::string path = light.cast<std::string>();
    py::gil_scoped_release nogil;
    rd::read_lighting(path, d, L);
  } else if (py::isinstance<ibl::ilf::SHGrid>(light)) {
    L->grid = light.cast<ibl::ilf::SHGrid>();
  } else if (py::isinstance<ibl::lights::LightSet>(light)) {
    const auto& set = light.cast<const ibl::lights::LightSet&>();
    std::vector<bool> shadow(set.lights.size(), false);
    for (size_t i = 0; i < shadow.size() && static_cast<int>(i) < shadows; ++i) shadow[i] = true;
    rd::add_light_set(set, shadow, L);
  } else if (py::isinstance<ibl::sh::Coeffs>(light)) {
    L->environment = light.cast<ibl::sh::Coeffs>();
  } else if (py::isinstance<py::array>(light) && py::reinterpret_borrow<py::array>(light).ndim() == 3 &&
             py::reinterpret_borrow<py::array>(light).shape(2) >= 3) {
    ibl::Image img = to_checked_image(light, "render: light");
    ibl::sphere::Mapping mp = mapping_of(mapping, img.width(), img.height());
    ibl::sphere::EnvMap env(std::move(img), mp);
    py::gil_scoped_release nogil;
    L->environment = ibl::sh::project(env, bands);
  } else {
    L->environment = coeffs_arg(light, "render: light");
  }
}

}  // namespace

void init_render(py::module_& m) {
  m.def(
      "render",
      [](py::handle light, py::object mesh, py::object camera, const std::string& object_kind, py::handle at,
         double size, int triangles, py::handle albedo, double gloss, double exponent, const std::string& lobe,
         double floor_size, int shadows, int bands, int width, int height, double fov, py::handle background,
         const std::string& mapping, bool coverage, py::object progress) -> py::object {
        if (lobe != "phong" && lobe != "blinn")
          ibl::fail(ibl::ErrorKind::Value, "render: lobe must be phong or blinn (got {})", lobe);
        if (shadows < 0 || shadows > 16)
          ibl::fail(ibl::ErrorKind::Value, "render: shadows must be in 0..16 (got {})", shadows);
        if (bands < 1 || bands > 9) ibl::fail(ibl::ErrorKind::Value, "render: bands must be in 1..9 (got {})", bands);
        ibl::require_number("render: gloss", gloss, 0, 1);
        ibl::require_number("render: exponent", exponent, 1, 10000);
        ibl::require_number("render: floor_size", floor_size, 0, 1000);
        rd::FrameDesc d;
        rd::ObjectDesc od;
        od.scene = object_kind;
        od.size = size;
        od.triangles = triangles;
        od.at = to_vec3(at, "render: at");
        ibl::require_point("render: at", od.at);
        if (camera.is_none()) {
          d.camera.width = width;
          d.camera.height = height;
          d.camera.target = od.at;
          d.camera.eye = od.at + ibl::Vec3{0, 0.5, 1.6};
          d.camera.fov_y_deg = fov;
        } else {
          d.camera = camera.cast<ibl::geometry::Camera>();
        }
        ibl::geometry::validate_camera(d.camera, "render: camera");
        d.background = to_vec3(background, "render: background");
        ibl::geometry::TriMesh object, floor;
        {
          py::gil_scoped_release nogil;
          if (mesh.is_none()) {
            if (!(size > 0) && (object_kind == "blob" || object_kind == "sphere"))
              ibl::fail(ibl::ErrorKind::Value, "render: size must be > 0 for the {}", object_kind);
            object = rd::make_object(od);
          }
        }
        if (!mesh.is_none()) {
          object = mesh.cast<ibl::geometry::TriMesh>();
          if (!object.has_normals()) object = ibl::geometry::with_normals(object);
        }
        ibl::Vec3 lo, hi;
        object.bounds(&lo, &hi);
        if (floor_size > 0) {  // just under the object, centred under `at` (the blob) or the mesh's bounds
          floor = ibl::geometry::make_floor(floor_size, lo.y - 1e-3);
          ibl::Vec3 c = mesh.is_none() ? od.at : (lo + hi) * 0.5;
          floor.transform(1.0, {c.x, 0, c.z});
        }
        rd::Material mat{to_vec3(albedo, "render: albedo"), ibl::Vec3{1, 1, 1} * gloss, exponent,
                         lobe == "blinn" ? rd::Lobe::BlinnPhong : rd::Lobe::Phong};
        d.objects = {{&object, mat}};
        if (floor_size > 0) d.objects.push_back({&floor, rd::Material{{0.5, 0.5, 0.5}, {0, 0, 0}, 1}});
        if (py::isinstance<py::list>(light) || py::isinstance<py::tuple>(light)) {
          for (auto item : light) add_lighting(item, bands, shadows, mapping, &d.lighting);
        } else {
          add_lighting(light, bands, shadows, mapping, &d.lighting);
        }
        Progress pr(progress);
        rd::RenderResult r;
        {
          py::gil_scoped_release nogil;
          r = rd::render_cpu(d, pr.fn());
        }
        pr.rethrow();
        if (coverage) return py::make_tuple(to_array(std::move(r.color)), to_array(std::move(r.coverage), true));
        return to_array(std::move(r.color));
      },
      py::arg("light"), py::arg("mesh") = py::none(), py::arg("camera") = py::none(), py::arg("object") = "blob",
      py::arg("at") = py::make_tuple(0, 0, 0), py::arg("size") = rd::ObjectDesc{}.size,
      py::arg("triangles") = rd::ObjectDesc{}.triangles, py::arg("albedo") = py::make_tuple(0.75, 0.75, 0.75),
      py::arg("gloss") = 0.0, py::arg("exponent") = rd::Material{}.exponent, py::arg("lobe") = "phong",
      py::arg("floor_size") = 6.0, py::arg("shadows") = rd::LightingReadDesc{}.shadows,
      py::arg("bands") = rd::LightingReadDesc{}.bands, py::arg("width") = 1024, py::arg("height") = 768,
      py::arg("fov") = 40.0, py::arg("background") = py::make_tuple(0, 0, 0), py::arg("mapping") = "latlong",
      py::arg("coverage") = false, py::arg("progress") = py::none(),
      R"doc(Renders an object under a lighting with the CPU reference renderer, as `iblkit render --backend cpu`:
an (H, W, 3) float32 radiance array (with coverage=True also the (H, W) coverage).

light: a lighting file path (.shgrid, iblkit.sh/1, iblkit.lights/1, iblkit.nearfield/1 or a probe
image), an SHCoeffs / (K, 3) array, an ilf.SHGrid, a LightSet (its first `shadows` lights cast
shadows), a probe image array (projected to `bands` SH bands, in `mapping`), or a list of them.
mesh: a TriMesh (with normals, or given them); default the CLI's object: `object` = "blob" (of
`triangles` triangles), "sphere" or a mesh file, `size` metres, centred at `at`; both on a
grey floor of floor_size metres (0: none). camera: a Camera (default: the CLI's, looking at `at` from
at + (0, 0.5, 1.6), width × height, fov degrees). Material: albedo, gloss (the Phong lobe's weight),
exponent, lobe phong|blinn. Releases the GIL; progress(stage, fraction).)doc");
}

}  // namespace iblpy
