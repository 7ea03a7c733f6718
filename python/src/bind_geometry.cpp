// geometry/: the one mesh type (TriMesh, the library's geometry::TriMesh) and the one pinhole camera
// (Camera, geometry::Camera, with its iblkit.camera/1 JSON).
#include "common.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "iblkit/augment/run_composite.h"
#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/camera_io.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/geometry/mesh_io.h"
#include "iblkit/render/objects.h"

namespace iblpy {

namespace {

using ibl::geometry::Camera;
using ibl::geometry::TriMesh;

TriMesh make_mesh(py::handle positions, py::handle triangles, py::object normals, py::object uvs) {
  TriMesh mesh;
  mesh.positions = to_vec3s(positions, "TriMesh: positions");
  py::array t = py::array::ensure(triangles);
  if (!t || (t.dtype().kind() != 'i' && t.dtype().kind() != 'u'))
    throw py::type_error("TriMesh: triangles must be an integer array of shape (F, 3)");
  if (t.ndim() != 2 || t.shape(1) != 3) throw py::value_error("TriMesh: triangles must have shape (F, 3)");
  auto ti = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(t);
  for (py::ssize_t i = 0; i < ti.shape(0); ++i) {
    std::array<uint32_t, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      int64_t v = ti.at(i, k);
      if (v < 0 || v >= static_cast<int64_t>(mesh.positions.size()))
        ibl::fail(ibl::ErrorKind::Value, "TriMesh: triangle {} names vertex {} of {}", i, v, mesh.positions.size());
      tri[k] = static_cast<uint32_t>(v);
    }
    mesh.triangles.push_back(tri);
  }
  if (!normals.is_none()) mesh.normals = to_vec3s(normals, "TriMesh: normals");
  if (!uvs.is_none()) {
    auto u = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(uvs);
    if (!u || u.ndim() != 2 || u.shape(1) != 2) throw py::value_error("TriMesh: uvs must have shape (V, 2)");
    for (py::ssize_t i = 0; i < u.shape(0); ++i) mesh.uvs.push_back({u.at(i, 0), u.at(i, 1)});
  }
  for (auto& p : mesh.positions) ibl::require_point("TriMesh: vertex", p);
  mesh.validate("TriMesh");
  return mesh;
}

}  // namespace

void init_geometry(py::module_& m) {
  py::class_<TriMesh>(m, "TriMesh",
                      R"doc(A triangle mesh (the library's geometry::TriMesh): positions (V, 3) in metres, triangles
(F, 3) vertex indices counter-clockwise seen from the front, optional unit vertex normals (V, 3) and
UVs (V, 2). The array properties are copies.)doc")
      .def(py::init(&make_mesh), py::arg("positions"), py::arg("triangles"), py::arg("normals") = py::none(),
           py::arg("uvs") = py::none(),
           "From (V, 3) positions and (F, 3) integer triangles (checked: indices in range, finite).")
      .def_property_readonly(
          "positions", [](const TriMesh& t) { return vec3_array(t.positions); }, "(V, 3) float64 positions.")
      .def_property_readonly(
          "triangles",
          [](const TriMesh& t) {
            py::array_t<uint32_t> a({static_cast<py::ssize_t>(t.triangles.size()), py::ssize_t(3)});
            std::memcpy(a.mutable_data(), t.triangles.data(), t.triangles.size() * sizeof(t.triangles[0]));
            return a;
          },
          "(F, 3) uint32 vertex indices.")
      .def_property_readonly(
          "normals",
          [](const TriMesh& t) -> py::object {
            if (!t.has_normals()) return py::none();
            return vec3_array(t.normals);
          },
          "(V, 3) vertex normals, or None.")
      .def_property_readonly(
          "uvs",
          [](const TriMesh& t) -> py::object {
            if (!t.has_uvs()) return py::none();
            py::array_t<double> a({static_cast<py::ssize_t>(t.uvs.size()), py::ssize_t(2)});
            for (size_t i = 0; i < t.uvs.size(); ++i) {
              a.mutable_at(i, 0) = t.uvs[i].x;
              a.mutable_at(i, 1) = t.uvs[i].y;
            }
            return a;
          },
          "(V, 2) texture coordinates, or None.")
      .def_property_readonly("vertex_count", &TriMesh::vertex_count)
      .def_property_readonly("triangle_count", &TriMesh::triangle_count)
      .def("total_area", &TriMesh::total_area, "Σ of the triangle areas, m².")
      .def(
          "bounds",
          [](const TriMesh& t) {
            ibl::Vec3 lo, hi;
            t.bounds(&lo, &hi);
            return py::make_tuple(vec3_tuple(lo), vec3_tuple(hi));
          },
          "(min, max) corners of the axis-aligned bounds.")
      .def(
          "with_normals", [](const TriMesh& t, double crease) { return ibl::geometry::with_normals(t, crease); },
          py::arg("crease_deg") = 40.0,
          "A copy with vertex normals, smooth except across edges sharper than crease_deg.")
      .def(
          "transformed",
          [](const TriMesh& t, double scale, py::handle translation, py::object rotation) {
            TriMesh c = t;
            ibl::Mat3 R = rotation.is_none() ? ibl::Mat3::identity() : to_mat3(rotation, "transformed: rotation");
            c.transform(R, scale, to_vec3(translation, "transformed: translation"));
            return c;
          },
          py::arg("scale") = 1.0, py::arg("translation") = py::make_tuple(0, 0, 0), py::arg("rotation") = py::none(),
          "A copy with p → rotation·(scale·p) + translation.")
      .def("__repr__",
           [](const TriMesh& t) {
             return fmt::format("TriMesh({} vertices, {} triangles)", t.vertex_count(), t.triangle_count());
           })
      .def_static(
          "load",
          [](const std::string& path) {
            py::gil_scoped_release nogil;
            return ibl::geometry::read_mesh(path);
          },
          py::arg("path"), "Reads a mesh file (OBJ, PLY, glTF, FBX … through assimp), every part joined, triangulated.")
      .def(
          "save_obj", [](const TriMesh& t, const std::string& path) { ibl::geometry::write_obj(path, t); },
          py::arg("path"), "Writes positions, UVs and triangles as Wavefront OBJ.")
      .def_static(
          "sphere",
          [](py::handle c, double r, int rings, int segments, bool inward) {
            return ibl::geometry::make_sphere(to_vec3(c, "sphere: center"),
                                              ibl::require_number("sphere: radius", r, 1e-9, 1e6),
                                              std::clamp(rings, 3, 4096), std::clamp(segments, 3, 8192), inward);
          },
          py::arg("center") = py::make_tuple(0, 0, 0), py::arg("radius") = 0.5, py::arg("rings") = 32,
          py::arg("segments") = 64, py::arg("inward") = false, "A UV sphere with exact radial normals.")
      .def_static(
          "box",
          [](py::handle lo, py::handle hi, bool inward) {
            ibl::Vec3 a = to_vec3(lo, "box: lo"), b = to_vec3(hi, "box: hi");
            ibl::require_box("box", a, b, true);
            return ibl::geometry::make_box(a, b, inward);
          },
          py::arg("lo"), py::arg("hi"), py::arg("inward") = false,
          "A closed axis-aligned box, front outwards (inwards: a room).")
      .def_static(
          "floor",
          [](double size, double height) {
            return ibl::geometry::make_floor(ibl::require_number("floor: size", size, 1e-9, 1e6), height);
          },
          py::arg("size"), py::arg("height") = 0.0, "A square of side `size` in the plane y = height facing +Y.")
      .def_static(
          "object",
          [](const std::string& kind, double size, int triangles, py::handle at) {
            const ibl::render::ObjectDesc d{kind, size, triangles, to_vec3(at, "object: at")};
            py::gil_scoped_release nogil;
            return ibl::render::make_object(d);
          },
          py::arg("kind") = ibl::augment::inserted_object_defaults().scene,
          py::arg("size") = ibl::augment::inserted_object_defaults().size,
          py::arg("triangles") = ibl::augment::inserted_object_defaults().triangles,
          py::arg("at") = py::make_tuple(0, 0, 0),
          R"doc(The object `iblkit composite` and `iblkit lab photograph --object` insert: "blob" (a bunny-sized
procedural object), "sphere", or a mesh file, its largest extent `size` metres, centred at `at`.)doc");

  py::class_<Camera>(m, "Camera",
                     R"doc(The pinhole camera of every renderer (the library's geometry::Camera): eye, target, up,
vertical field of view in degrees and the frame size; pixel (i, j) has its centre at (j + ½, i + ½),
row 0 at the top.)doc")
      .def(py::init([](py::handle eye, py::handle target, py::handle up, double fov_y_deg, int width, int height) {
             Camera c;
             c.eye = to_vec3(eye, "Camera: eye");
             c.target = to_vec3(target, "Camera: target");
             c.up = to_vec3(up, "Camera: up");
             c.fov_y_deg = fov_y_deg;
             c.width = width;
             c.height = height;
             ibl::geometry::validate_camera(c, "Camera");
             return c;
           }),
           py::arg("eye") = py::make_tuple(0, 0.3, 1.2), py::arg("target") = py::make_tuple(0, 0, 0),
           py::arg("up") = py::make_tuple(0, 1, 0), py::arg("fov_y_deg") = 40.0, py::arg("width") = 1024,
           py::arg("height") = 768, "Checked: distinct eye and target, up not along the view.")
      .def_property(
          "eye", [](const Camera& c) { return vec3_tuple(c.eye); },
          [](Camera& c, py::handle v) { c.eye = to_vec3(v, "Camera.eye"); })
      .def_property(
          "target", [](const Camera& c) { return vec3_tuple(c.target); },
          [](Camera& c, py::handle v) { c.target = to_vec3(v, "Camera.target"); })
      .def_property(
          "up", [](const Camera& c) { return vec3_tuple(c.up); },
          [](Camera& c, py::handle v) { c.up = to_vec3(v, "Camera.up"); })
      .def_readwrite("fov_y_deg", &Camera::fov_y_deg, "Vertical field of view, degrees.")
      .def_readwrite("width", &Camera::width, "Frame width, pixels.")
      .def_readwrite("height", &Camera::height, "Frame height, pixels.")
      .def_property(
          "intrinsics",
          [](const Camera& c) -> py::object {
            if (!c.intrinsics) return py::none();
            return py::make_tuple(c.intrinsics->fx, c.intrinsics->fy, c.intrinsics->cx, c.intrinsics->cy);
          },
          [](Camera& c, py::object v) {
            if (v.is_none()) {
              c.intrinsics.reset();
              return;
            }
            auto t = v.cast<std::vector<double>>();
            if (t.size() != 4) throw py::value_error("Camera.intrinsics: (fx, fy, cx, cy) in pixels, or None");
            c.intrinsics = ibl::geometry::Intrinsics{t[0], t[1], t[2], t[3]};
            ibl::geometry::require_lens(c, "Camera.intrinsics");
          },
          "(fx, fy, cx, cy) in pixels (continuous coordinates: pixel i's centre at i + ½), or None: the pinhole of "
          "fov_y_deg with the principal point at the centre (docs/conventions.md, Camera).")
      .def_property(
          "distortion",
          [](const Camera& c) {
            const auto& d = c.distortion;
            return py::make_tuple(d.k1, d.k2, d.p1, d.p2, d.k3);
          },
          [](Camera& c, py::handle v) {
            auto t = v.cast<std::vector<double>>();
            if (t.size() != 5) throw py::value_error("Camera.distortion: (k1, k2, p1, p2, k3), OpenCV's model");
            c.distortion = ibl::geometry::Distortion{t[0], t[1], t[2], t[3], t[4]};
            ibl::geometry::require_lens(c, "Camera.distortion");
          },
          "Brown–Conrady (k1, k2, p1, p2, k3) with OpenCV's signs; needs intrinsics.")
      .def(
          "project",
          [](const Camera& c, py::handle point) -> py::object {
            ibl::geometry::require_camera(c);
            const auto p = c.project(to_vec3(point, "Camera.project: point"));
            if (!p) return py::none();
            return py::make_tuple(p->x, p->y);
          },
          py::arg("point"),
          "The continuous pixel position (x, y) where a world point appears, through the lens; None behind the eye.")
      .def(
          "ray_directions",
          [](const Camera& c) {
            ibl::geometry::require_camera(c);
            if (c.width < 1 || c.height < 1 || c.width > 16384 || c.height > 16384)
              ibl::fail(ibl::ErrorKind::Value, "Camera: frame size {}x{}", c.width, c.height);
            py::array_t<double> a({py::ssize_t(c.height), py::ssize_t(c.width), py::ssize_t(3)});
            double* p = a.mutable_data();
            for (int y = 0; y < c.height; ++y)
              for (int x = 0; x < c.width; ++x) {
                ibl::Vec3 d = c.pixel_direction(x, y);
                size_t i = (static_cast<size_t>(y) * c.width + x) * 3;
                p[i] = d.x;
                p[i + 1] = d.y;
                p[i + 2] = d.z;
              }
            return a;
          },
          "(H, W, 3) unit world directions through every pixel centre.")
      .def(
          "view_matrix",
          [](const Camera& c) {
            auto v = c.view();
            py::array_t<float> a({4, 4});
            for (int r = 0; r < 4; ++r)
              for (int col = 0; col < 4; ++col) a.mutable_at(r, col) = v[col * 4 + r];
            return a;
          },
          "World → eye 4×4 matrix (GL lookAt; row-major here).")
      .def(
          "projection_matrix",
          [](const Camera& c) {
            auto v = c.projection();
            py::array_t<float> a({4, 4});
            for (int r = 0; r < 4; ++r)
              for (int col = 0; col < 4; ++col) a.mutable_at(r, col) = v[col * 4 + r];
            return a;
          },
          "Eye → clip 4×4 matrix (GL perspective; row-major here).")
      .def(
          "to_json", [](const Camera& c) { return ibl::geometry::camera_to_json(c).dump(2); },
          "The iblkit.camera/1 text (with the size).")
      .def_static(
          "from_json",
          [](const std::string& text) {
            nlohmann::json j;
            try {
              j = nlohmann::json::parse(text);
            } catch (const nlohmann::json::exception& e) {
              ibl::fail(ibl::ErrorKind::Format, "Camera.from_json: not JSON ({})", e.what());
            }
            return ibl::geometry::camera_from_json(j, "json");
          },
          py::arg("text"), "Parses iblkit.camera/1 text (width and height 0 when absent).")
      .def(
          "save", [](const Camera& c, const std::string& p) { ibl::geometry::write_camera(p, c); }, py::arg("path"),
          "Writes an iblkit.camera/1 file.")
      .def_static("load", &ibl::geometry::read_camera, py::arg("path"), "Reads an iblkit.camera/1 file.")
      .def("__repr__", [](const Camera& c) {
        return fmt::format("Camera(eye=({:g}, {:g}, {:g}), target=({:g}, {:g}, {:g}), fov_y_deg={:g}, {}x{})", c.eye.x,
                           c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.fov_y_deg, c.width, c.height);
      });
}

}  // namespace iblpy
