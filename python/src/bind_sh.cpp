// sh/: the SH coefficient type (SHCoeffs, the library's sh::Coeffs), projection, evaluation,
// irradiance, rotation, windowing and the export layouts.
#include "common.h"

#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/io/image_io.h"
#include "iblkit/sh/basis.h"
#include "iblkit/sh/coeffs.h"
#include "iblkit/sh/convolve.h"
#include "iblkit/sh/export.h"
#include "iblkit/sh/project.h"
#include "iblkit/sh/rotate.h"

namespace iblpy {

namespace {

using ibl::sh::Coeffs;

Coeffs coeffs_from_array(py::handle obj, const char* what) {
  py::array a = py::array::ensure(obj);
  if (!a || (a.dtype().kind() != 'f' && a.dtype().kind() != 'i'))
    throw py::type_error(fmt::format("{}: expected a float array of shape (K, 3)", what));
  if (a.ndim() != 2 || a.shape(1) != 3 || a.shape(0) < 1)
    throw py::value_error(fmt::format("{}: expected shape (K, 3) with K = bands², got ndim {}", what, a.ndim()));
  int K = static_cast<int>(a.shape(0)), bands = static_cast<int>(std::lround(std::sqrt(double(K))));
  if (bands * bands != K)
    throw py::value_error(fmt::format("{}: K = {} coefficients is not a square (bands²)", what, K));
  auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  Coeffs c;
  c.bands = bands;
  c.c.resize(K);
  for (int k = 0; k < K; ++k) c.c[k] = {d.at(k, 0), d.at(k, 1), d.at(k, 2)};
  c.validate(what);
  return c;
}

nlohmann::json parse_json_text(const std::string& text, const char* what) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    ibl::fail(ibl::ErrorKind::Format, "{}: not JSON ({})", what, e.what());
  }
}

// The rotation R checked to be orthogonal with determinant +1 (to 1e-6).
ibl::Mat3 rotation_arg(py::handle obj, const char* what) {
  ibl::Mat3 R = to_mat3(obj, what);
  ibl::Mat3 P = R * R.transposed();
  double err = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) err = std::max(err, std::abs(P.m[i][j] - (i == j ? 1.0 : 0.0)));
  double det = R.m[0][0] * (R.m[1][1] * R.m[2][2] - R.m[1][2] * R.m[2][1]) -
               R.m[0][1] * (R.m[1][0] * R.m[2][2] - R.m[1][2] * R.m[2][0]) +
               R.m[0][2] * (R.m[1][0] * R.m[2][1] - R.m[1][1] * R.m[2][0]);
  if (!(err < 1e-6) || !(det > 0))
    ibl::fail(ibl::ErrorKind::Value, "{}: not a rotation (R·Rᵀ off identity by {:g}, det {:g})", what, err, det);
  return R;
}

std::vector<ibl::Vec3> unit_directions(py::handle obj, const char* what) {
  auto v = to_vec3s(obj, what);
  for (auto& d : v) d = ibl::require_direction(what, d);
  return v;
}

}  // namespace

// Also used by bind_lights.cpp and bind_render.cpp: an SHCoeffs or a (K, 3) array.
Coeffs coeffs_arg(py::handle obj, const char* what) {
  if (py::isinstance<Coeffs>(obj)) return obj.cast<Coeffs>();
  return coeffs_from_array(obj, what);
}

void init_sh(py::module_& m) {
  py::class_<Coeffs>(m, "SHCoeffs", py::buffer_protocol(),
                     R"doc(Real SH coefficients of RGB radiance (the library's sh::Coeffs): orthonormal basis, no
Condon–Shortley phase, index k = l(l+1)+m, bands = L+1 (3 bands = 9 coefficients).
`coefficients` is a writable (K, 3) float64 view of the library's storage (no copy); the object also
supports the buffer protocol, so numpy.asarray(c) is the same view.)doc")
      .def(py::init([](int bands) {
             if (bands < 1 || bands > ibl::sh::kMaxBands)
               ibl::fail(ibl::ErrorKind::Value, "bands must be in 1..{} (got {})", ibl::sh::kMaxBands, bands);
             return Coeffs(bands);
           }),
           py::arg("bands"), "bands² zero coefficients.")
      .def(py::init([](py::array coefficients) { return coeffs_from_array(coefficients, "SHCoeffs: coefficients"); }),
           py::arg("coefficients"), "From a (K, 3) array, K = bands² (values copied, must be finite).")
      .def_buffer([](Coeffs& c) {
        return py::buffer_info(reinterpret_cast<double*>(c.c.data()), sizeof(double),
                               py::format_descriptor<double>::format(), 2,
                               {static_cast<py::ssize_t>(c.c.size()), py::ssize_t(3)},
                               {static_cast<py::ssize_t>(sizeof(ibl::Vec3)), static_cast<py::ssize_t>(sizeof(double))});
      })
      .def_readonly("bands", &Coeffs::bands, "Number of bands L+1.")
      .def_property(
          "coefficients",
          [](py::object self) {
            Coeffs& c = self.cast<Coeffs&>();
            static_assert(sizeof(ibl::Vec3) == 3 * sizeof(double));
            return py::array_t<double>(
                {static_cast<py::ssize_t>(c.c.size()), py::ssize_t(3)},
                {static_cast<py::ssize_t>(sizeof(ibl::Vec3)), static_cast<py::ssize_t>(sizeof(double))},
                reinterpret_cast<double*>(c.c.data()), self);
          },
          [](Coeffs& c, py::array values) {
            Coeffs n = coeffs_from_array(values, "SHCoeffs.coefficients");
            if (n.bands != c.bands)
              throw py::value_error(
                  fmt::format("SHCoeffs.coefficients: expected ({}, 3), got {} coefficients", c.c.size(), n.c.size()));
            c.c = n.c;  // same size: views handed out stay valid
          },
          "(K, 3) float64 view of the coefficients (RGB per coefficient, index order).")
      .def("__len__", [](const Coeffs& c) { return c.c.size(); })
      .def("__repr__",
           [](const Coeffs& c) {
             return fmt::format("SHCoeffs(bands={}, c00=({:.6g}, {:.6g}, {:.6g}))", c.bands,
                                c.c.empty() ? 0.0 : c.c[0].x, c.c.empty() ? 0.0 : c.c[0].y,
                                c.c.empty() ? 0.0 : c.c[0].z);
           })
      .def("resized", &Coeffs::resized, py::arg("bands"), "The first `bands` bands (truncated, or zero-padded).")
      .def(
          "to_json", [](const Coeffs& c) { return ibl::sh::to_json_text(c); }, "The iblkit.sh/1 file text.")
      .def_static(
          "from_json",
          [](const std::string& text) {
            return ibl::sh::coeffs_from_json(parse_json_text(text, "SHCoeffs.from_json"), "json");
          },
          py::arg("text"), "Parses iblkit.sh/1 text.")
      .def(
          "save", [](const Coeffs& c, const std::string& path) { ibl::sh::write_coeffs(path, c); }, py::arg("path"),
          "Writes an iblkit.sh/1 file (atomically).")
      .def_static("load", &ibl::sh::read_coeffs, py::arg("path"), "Reads an iblkit.sh/1 file.")
      .def(py::pickle(
          [](const Coeffs& c) { return ibl::sh::to_json_text(c); },
          [](const std::string& t) { return ibl::sh::coeffs_from_json(nlohmann::json::parse(t), "pickle"); }));

  m.def(
      "sh_project",
      [](py::handle img, int bands, const std::string& mapping, py::object window, double window_width,
         double dead_angle, py::object progress) {
        py::array_t<float> a = image_array(img, "sh_project: img");
        ibl::ImageView v = view_of(a);
        ibl::sphere::Mapping mp = mapping_of(mapping, v.width(), v.height(), dead_angle);
        ibl::sh::WindowDesc wd;
        if (!window.is_none()) wd.kind = ibl::sh::parse_window(window.cast<std::string>());
        wd.width = window_width;
        Progress pr(progress);
        Coeffs c;
        {
          py::gil_scoped_release nogil;
          c = ibl::sh::project(v, mp, bands, pr.fn());
        }
        pr.rethrow();
        for (const auto& e : c.c)
          if (!ibl::is_finite(e)) {  // NaN/Inf in the image: the library's pixel check names the pixel
            ibl::Image copy = to_image(img, "sh_project: img");
            ibl::io::check_pixels(copy, "sh_project: img", false);
            ibl::fail(ibl::ErrorKind::Value, "sh_project: img: the projection is not finite (pixel values too large)");
          }
        if (wd.kind != ibl::sh::Window::None) c = ibl::sh::apply_window(c, wd);
        return c;
      },
      py::arg("img"), py::arg("bands") = 3, py::arg("mapping") = "latlong", py::arg("window") = py::none(),
      py::arg("window_width") = 0.0, py::arg("dead_angle") = 0.0, py::arg("progress") = py::none(),
      R"doc(Projects an environment map onto SH, as `iblkit sh`: c_lm = ∫ L(ω) Y_lm(ω) dω with exact
pixel solid angles (lat-long: the exact projection of the piecewise-constant image).

img: (H, W, C) float array (float32 with contiguous pixels is read in place, without a copy; any
other layout is copied once). Grey images repeat channel 0; extra channels are ignored.
bands: 1..32. mapping: latlong, mirrorball, angular, hcross, vcross, cubestrip, octahedral or auto.
window: None, "hanning", "lanczos" or "deringing" (window_width W: 0 picks W = bands).
Releases the GIL; progress(stage, fraction) is called as the rows are done. Negative pixels are
projected as they are (the projection is linear); NaN/Inf raise InvalidValue naming the pixel.)doc");

  m.def(
      "sh_eval",
      [](py::handle coeffs, py::handle directions) {
        Coeffs c = coeffs_arg(coeffs, "sh_eval: coeffs");
        auto d = unit_directions(directions, "sh_eval: directions");
        std::vector<ibl::Vec3> out(d.size());
        {
          py::gil_scoped_release nogil;
          for (size_t i = 0; i < d.size(); ++i) out[i] = c.evaluate(d[i]);
        }
        return vec3_array(out);
      },
      py::arg("coeffs"), py::arg("directions"),
      "Radiance Σ c_k Y_k(d) at each direction ((N, 3), normalised here): an (N, 3) array.");

  m.def(
      "sh_irradiance",
      [](py::handle coeffs, py::handle normals) {
        Coeffs c = coeffs_arg(coeffs, "sh_irradiance: coeffs");
        auto n = unit_directions(normals, "sh_irradiance: normals");
        std::vector<ibl::Vec3> out(n.size());
        {
          py::gil_scoped_release nogil;
          Coeffs e = ibl::sh::irradiance(c);
          for (size_t i = 0; i < n.size(); ++i) out[i] = e.evaluate(n[i]);
        }
        return vec3_array(out);
      },
      py::arg("coeffs"), py::arg("normals"),
      "Irradiance E(n) = ∫ L(ω) max(n·ω, 0) dω (W/m²) of SH radiance at each normal ((N, 3)): an (N, 3) array.");

  m.def(
      "sh_irradiance_coeffs",
      [](py::handle coeffs) { return ibl::sh::irradiance(coeffs_arg(coeffs, "sh_irradiance_coeffs: coeffs")); },
      py::arg("coeffs"), "The irradiance as SH: radiance convolved with the clamped cosine (Â_l: π, 2π/3, π/4, …).");

  m.def(
      "sh_rotate",
      [](py::handle coeffs, py::handle rotation) {
        Coeffs c = coeffs_arg(coeffs, "sh_rotate: coeffs");
        ibl::Mat3 R = rotation_arg(rotation, "sh_rotate: rotation");
        py::gil_scoped_release nogil;
        return ibl::sh::rotate(c, R);
      },
      py::arg("coeffs"), py::arg("rotation"),
      "The environment turned by the 3×3 rotation R: g(d) = f(Rᵀ d) (as convert's rotation). Exact for any bands.");

  m.def(
      "sh_window",
      [](py::handle coeffs, const std::string& kind, double width) {
        ibl::sh::WindowDesc wd;
        wd.kind = ibl::sh::parse_window(kind);
        wd.width = width;
        Coeffs c = coeffs_arg(coeffs, "sh_window: coeffs");
        py::gil_scoped_release nogil;
        return ibl::sh::apply_window(c, wd);
      },
      py::arg("coeffs"), py::arg("kind") = "hanning", py::arg("width") = 0.0,
      "Windows radiance coefficients against ringing: none, hanning, lanczos (width W, 0: bands) or deringing.");

  m.def(
      "sh_export",
      [](py::handle coeffs, const std::string& format) {
        return ibl::sh::export_text(coeffs_arg(coeffs, "sh_export: coeffs"), ibl::sh::parse_export_format(format));
      },
      py::arg("coeffs"), py::arg("format") = "iblkit",
      R"doc(The file text of an export layout, as `iblkit sh --format`: iblkit (iblkit.sh/1 JSON),
threejs (SphericalHarmonics3 JSON), filament (cmgen's sh.txt), gltf (EXT_lights_image_based).)doc");

  m.def(
      "sh_layout",
      [](py::handle coeffs, const std::string& format) {
        Coeffs c = coeffs_arg(coeffs, "sh_layout: coeffs");
        Coeffs out;
        switch (ibl::sh::parse_export_format(format)) {
          case ibl::sh::ExportFormat::ThreeJs:
            out = ibl::sh::to_threejs(c);
            break;
          case ibl::sh::ExportFormat::Filament:
            out = ibl::sh::to_filament(c);
            break;
          case ibl::sh::ExportFormat::Gltf:
            out = ibl::sh::to_gltf(c);
            break;
          case ibl::sh::ExportFormat::Iblkit:
            out = c;
            break;
        }
        return vec3_array(out.c);
      },
      py::arg("coeffs"), py::arg("format"),
      "The values a layout stores as a (9, 3) array (threejs, filament, gltf; iblkit: the coefficients).");

  m.def(
      "sh_from_layout",
      [](py::handle values, const std::string& format) {
        Coeffs c = coeffs_from_array(values, "sh_from_layout: values");
        switch (ibl::sh::parse_export_format(format)) {
          case ibl::sh::ExportFormat::Filament:
            return ibl::sh::from_filament(c);
          case ibl::sh::ExportFormat::Gltf:
            return ibl::sh::from_gltf(c);
          default:
            return c;  // threejs and iblkit store the coefficients themselves
        }
      },
      py::arg("values"), py::arg("format"), "Radiance coefficients back from a layout's (9, 3) values.");

  m.def(
      "sh_reconstruct",
      [](py::handle coeffs, int width, int height, const std::string& mapping) {
        Coeffs c = coeffs_arg(coeffs, "sh_reconstruct: coeffs");
        if (width < 1 || height < 1 || width > 16384 || height > 16384)
          ibl::fail(ibl::ErrorKind::Value, "sh_reconstruct: size {}x{} outside 1..16384", width, height);
        ibl::sphere::Mapping mp = mapping_of(mapping, width, height);
        ibl::Image img;
        {
          py::gil_scoped_release nogil;
          img = ibl::sh::reconstruct(c, mp);
        }
        return to_array(std::move(img));
      },
      py::arg("coeffs"), py::arg("width") = 128, py::arg("height") = 64, py::arg("mapping") = "latlong",
      "The radiance Σ c_k Y_k as an image of the mapping (pixels without a direction are 0): (H, W, 3) float32.");

  m.def(
      "sh_basis",
      [](int bands, py::handle directions) {
        auto d = unit_directions(directions, "sh_basis: directions");
        const int K = ibl::sh::coeff_count(bands);
        std::vector<double> tmp(K);
        ibl::sh::eval_basis(bands, d.empty() ? ibl::Vec3{0, 1, 0} : d[0], tmp.data());  // checks bands
        py::array_t<double> out({static_cast<py::ssize_t>(d.size()), static_cast<py::ssize_t>(K)});
        for (size_t i = 0; i < d.size(); ++i) ibl::sh::eval_basis(bands, d[i], out.mutable_data() + i * K);
        return out;
      },
      py::arg("bands"), py::arg("directions"), "Y_k(d) for k < bands² at each direction: an (N, bands²) array.");
}

}  // namespace iblpy
