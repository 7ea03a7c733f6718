// lights/: the light set type (LightSet, the library's lights::LightSet), extraction (median cut,
// variance cut, optimisation) and the irradiance error against a probe's exact ground truth.
#include "common.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/lights/evaluate.h"
#include "iblkit/lights/extract.h"
#include "iblkit/lights/gltf.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/sh/coeffs.h"
#include "iblkit/sh/convolve.h"
#include "iblkit/sphere/pointset.h"

namespace iblpy {

ibl::sh::Coeffs coeffs_arg(py::handle obj, const char* what);  // bind_sh.cpp

namespace {

using ibl::lights::LightSet;

ibl::sphere::EnvMap probe_arg(py::handle img, const std::string& mapping, double dead_angle, const char* what) {
  ibl::Image im = to_checked_image(img, what);
  ibl::sphere::Mapping mp = mapping_of(mapping, im.width(), im.height(), dead_angle);
  return ibl::sphere::EnvMap(std::move(im), mp);
}

LightSet make_set(py::handle directions, py::handle irradiance, py::object solid_angle, const std::string& method) {
  auto d = to_vec3s(directions, "LightSet: directions");
  auto e = to_vec3s(irradiance, "LightSet: irradiance");
  if (e.size() != d.size())
    throw py::value_error(fmt::format("LightSet: {} directions but {} irradiance rows", d.size(), e.size()));
  std::vector<double> sa(d.size(), 0.0);
  if (!solid_angle.is_none()) {
    auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(solid_angle);
    if (!a || a.ndim() != 1 || static_cast<size_t>(a.shape(0)) != d.size())
      throw py::value_error(fmt::format("LightSet: solid_angle must have shape ({},)", d.size()));
    for (size_t i = 0; i < d.size(); ++i) sa[i] = a.at(i);
  }
  LightSet s;
  s.method = method;
  for (size_t i = 0; i < d.size(); ++i) {
    ibl::lights::Light l;
    l.direction = ibl::require_direction(fmt::format("LightSet: light {} direction", i), d[i]);
    if (!ibl::is_finite(e[i]) || e[i].x < 0 || e[i].y < 0 || e[i].z < 0)
      ibl::fail(ibl::ErrorKind::Value, "LightSet: light {} irradiance ({}, {}, {}) must be finite and ≥ 0", i, e[i].x,
                e[i].y, e[i].z);
    l.irradiance = e[i];
    if (!std::isfinite(sa[i]) || sa[i] < 0 || sa[i] > ibl::kFourPi + 1e-9)
      ibl::fail(ibl::ErrorKind::Value, "LightSet: light {} solid angle {} outside [0, 4π]", i, sa[i]);
    l.solid_angle = sa[i];
    s.lights.push_back(l);
  }
  return s;
}

std::vector<ibl::Vec3> field(const LightSet& s, int which) {
  std::vector<ibl::Vec3> v;
  for (const auto& l : s.lights) v.push_back(which == 0 ? l.direction : l.irradiance);
  return v;
}

}  // namespace

// Also used by bind_render.cpp.
const LightSet& light_set_arg(py::handle obj) { return obj.cast<const LightSet&>(); }

void init_lights(py::module_& m) {
  py::class_<ibl::lights::ErrorStats>(
      m, "ErrorStats",
      "Irradiance error at a set of normals (Madsen & Laursen 2007 §5), per channel, averaged over RGB.")
      .def_readonly("mean_rel", &ibl::lights::ErrorStats::mean_rel, "Mean over normals of |E_est − E_gt| / E_gt.")
      .def_readonly("max_rel", &ibl::lights::ErrorStats::max_rel, "Max over normals of the same (the paper's Fig. 4).")
      .def_readonly("rms_rel", &ibl::lights::ErrorStats::rms_rel, "√(mean of the squared relative error).")
      .def_readonly("rms_abs", &ibl::lights::ErrorStats::rms_abs, "√(mean (E_est − E_gt)²) (Pedersen's RMS).")
      .def_property_readonly(
          "mean_est", [](const ibl::lights::ErrorStats& e) { return vec3_tuple(e.mean_est); },
          "Mean estimated irradiance (RGB).")
      .def_property_readonly(
          "mean_gt", [](const ibl::lights::ErrorStats& e) { return vec3_tuple(e.mean_gt); },
          "Mean ground-truth irradiance (RGB).")
      .def("__repr__", [](const ibl::lights::ErrorStats& e) {
        return fmt::format("ErrorStats(mean_rel={:.6g}, max_rel={:.6g}, rms_rel={:.6g}, rms_abs={:.6g})", e.mean_rel,
                           e.max_rel, e.rms_rel, e.rms_abs);
      });

  py::class_<LightSet>(m, "LightSet",
                       R"doc(Directional lights (the library's lights::LightSet): each light is a direction towards it
and the irradiance it delivers at normal incidence (RGB, W/m²), with the solid angle of the probe
region it stands for. The array properties are copies; build a new set to change it.)doc")
      .def(py::init(&make_set), py::arg("directions"), py::arg("irradiance"), py::arg("solid_angle") = py::none(),
           py::arg("method") = "given",
           "From (N, 3) directions (normalised here), (N, 3) irradiance and (N,) solid angles.")
      .def_readwrite("method", &LightSet::method, "How the set was made (median-cut, variance-cut, optimize, …).")
      .def_property_readonly(
          "directions", [](const LightSet& s) { return vec3_array(field(s, 0)); },
          "(N, 3) unit directions towards the lights.")
      .def_property_readonly(
          "irradiance", [](const LightSet& s) { return vec3_array(field(s, 1)); }, "(N, 3) RGB irradiance, W/m².")
      .def_property_readonly(
          "solid_angle",
          [](const LightSet& s) {
            py::array_t<double> a(static_cast<py::ssize_t>(s.lights.size()));
            for (size_t i = 0; i < s.lights.size(); ++i) a.mutable_at(i) = s.lights[i].solid_angle;
            return a;
          },
          "(N,) solid angle of each light's region, sr.")
      .def_property_readonly(
          "positions",
          [](const LightSet& s) -> py::object {
            bool any = false;
            std::vector<ibl::Vec3> p;
            for (const auto& l : s.lights) {
              any = any || l.position.has_value();
              p.push_back(l.position.value_or(ibl::Vec3{NAN, NAN, NAN}));
            }
            if (!any) return py::none();
            return vec3_array(p);
          },
          "(N, 3) positions of localised lights (fusion; NaN rows for lights without one), or None.")
      .def("__len__", [](const LightSet& s) { return s.lights.size(); })
      .def("__repr__",
           [](const LightSet& s) { return fmt::format("LightSet({} lights, method='{}')", s.lights.size(), s.method); })
      .def(
          "total_irradiance", [](const LightSet& s) { return vec3_tuple(ibl::lights::total_irradiance(s)); },
          "Σ of the lights' irradiance (RGB): ∫ L dω of the probe for every cut.")
      .def(
          "irradiance_at",
          [](const LightSet& s, py::handle normals) {
            auto n = to_vec3s(normals, "irradiance_at: normals");
            for (auto& d : n) d = ibl::require_direction("irradiance_at: normal", d);
            std::vector<ibl::Vec3> e;
            {
              py::gil_scoped_release nogil;
              e = ibl::lights::irradiance_from_lights(s.lights, n);
            }
            return vec3_array(e);
          },
          py::arg("normals"), "E(n) = Σ_i E_i max(0, n·d_i) at each normal: an (N, 3) array.")
      .def(
          "to_json", [](const LightSet& s) { return ibl::lights::to_json(s).dump(2); }, "The iblkit.lights/1 text.")
      .def_static(
          "from_json",
          [](const std::string& text) {
            nlohmann::json j;
            try {
              j = nlohmann::json::parse(text);
            } catch (const nlohmann::json::exception& e) {
              ibl::fail(ibl::ErrorKind::Format, "LightSet.from_json: not JSON ({})", e.what());
            }
            return ibl::lights::from_json(j, "json");
          },
          py::arg("text"), "Parses iblkit.lights/1 text.")
      .def(
          "save", [](const LightSet& s, const std::string& p) { ibl::lights::write_lights(p, s); }, py::arg("path"),
          "Writes an iblkit.lights/1 file (atomically).")
      .def_static("load", &ibl::lights::read_lights, py::arg("path"), "Reads an iblkit.lights/1 file.")
      .def(
          "to_gltf",
          [](const LightSet& s, double lux_per_unit) {
            ibl::lights::GltfDesc d;
            d.lux_per_unit = lux_per_unit;
            return ibl::lights::to_gltf(s, d).dump(2);
          },
          py::arg("lux_per_unit") = 1.0, "The set as glTF 2.0 JSON text (KHR_lights_punctual directional lights).");

  m.def(
      "lights",
      [](py::handle img, const std::string& method, int count, const std::string& mapping, double min_separation,
         int normals_level, int iterations, double tolerance, const std::string& init, double dead_angle,
         py::object progress) {
        ibl::lights::check_method(method);
        EnvArg arg(img, mapping, dead_angle, "lights: img", false);  // extract() validates the pixels itself
        const ibl::sphere::EnvMap& env = arg.env();
        ibl::lights::ExtractDesc d;
        d.method = method;
        d.count = count;
        d.min_separation_deg = min_separation;
        d.optimize.normals_level = normals_level;
        d.optimize.max_iterations = iterations;
        d.optimize.tolerance = tolerance;
        d.optimize.init = init;
        Progress pr(progress);
        d.progress = pr.fn();
        ibl::lights::Extraction ex;
        {
          py::gil_scoped_release nogil;
          ex = ibl::lights::extract(env, d);
        }
        pr.rethrow();
        return ex.set;
      },
      py::arg("img"), py::arg("method") = "median-cut", py::arg("count") = 16, py::arg("mapping") = "latlong",
      py::arg("min_separation") = 0.0, py::arg("normals_level") = 5, py::arg("iterations") = 1000,
      py::arg("tolerance") = 1e-6, py::arg("init") = "variance-cut", py::arg("dead_angle") = 0.0,
      py::arg("progress") = py::none(),
      R"doc(Directional lights from a probe, as `iblkit lights`: method median-cut, median-cut-2k (a power of
two), variance-cut or optimize (Levenberg–Marquardt on the irradiance at the 20·4^normals_level
icosphere normals, started from `init`'s cut, stopped at `tolerance`, at most `iterations` steps per
stage). min_separation: merge lights closer than this many degrees (0: off). The probe is checked
(NaN/Inf/negative pixels raise InvalidValue). Releases the GIL; progress(stage, fraction).)doc");

  m.def(
      "irradiance_ground_truth",
      [](py::handle img, py::handle normals, const std::string& mapping, double dead_angle, py::object progress) {
        ibl::sphere::EnvMap env = probe_arg(img, mapping, dead_angle, "irradiance_ground_truth: img");
        auto n = to_vec3s(normals, "irradiance_ground_truth: normals");
        for (auto& d : n) d = ibl::require_direction("irradiance_ground_truth: normal", d);
        Progress pr(progress);
        ibl::lights::GroundTruthDesc gd;
        gd.progress = pr.fn();
        std::vector<ibl::Vec3> e;
        {
          py::gil_scoped_release nogil;
          e = ibl::lights::irradiance_ground_truth(env, n, gd);
        }
        pr.rethrow();
        return vec3_array(e);
      },
      py::arg("img"), py::arg("normals"), py::arg("mapping") = "latlong", py::arg("dead_angle") = 0.0,
      py::arg("progress") = py::none(),
      "Exact irradiance E(n) = Σ_pixels L max(0, n·ω) dω of a probe at each normal: an (N, 3) array.");

  m.def(
      "icosphere_normals",
      [](int level) {
        ibl::lights::check_normals_level(level);
        return vec3_array(ibl::sphere::icosphere_face_centres(level));
      },
      py::arg("level") = 5,
      "The 20·4^level icosphere face centres the irradiance error is measured at (level 5: 20480).");

  m.def(
      "irradiance_error",
      [](py::handle img, py::handle estimate, const std::string& mapping, int normals_level, double floor_fraction,
         double dead_angle, py::object progress) {
        ibl::sphere::EnvMap env = probe_arg(img, mapping, dead_angle, "irradiance_error: img");
        ibl::lights::check_normals_level(normals_level);
        std::optional<LightSet> set;
        std::optional<ibl::sh::Coeffs> coeffs;
        if (py::isinstance<LightSet>(estimate))
          set = estimate.cast<LightSet>();
        else
          coeffs = coeffs_arg(estimate, "irradiance_error: estimate");
        ibl::lights::ErrorDesc ed;
        ed.floor_fraction = ibl::require_number("irradiance_error: floor_fraction", floor_fraction, 0, 1);
        Progress pr(progress);
        ibl::lights::GroundTruthDesc gd;
        gd.progress = pr.fn();
        ibl::lights::ErrorStats st;
        {
          py::gil_scoped_release nogil;
          auto normals = ibl::sphere::icosphere_face_centres(normals_level);
          auto gt = ibl::lights::irradiance_ground_truth(env, normals, gd);
          std::vector<ibl::Vec3> est(normals.size());
          if (set) {
            est = ibl::lights::irradiance_from_lights(set->lights, normals);
          } else {
            for (size_t k = 0; k < normals.size(); ++k) est[k] = ibl::sh::irradiance_at(*coeffs, normals[k]);
          }
          st = ibl::lights::compare_irradiance(est, gt, ed);
        }
        pr.rethrow();
        return st;
      },
      py::arg("img"), py::arg("estimate"), py::arg("mapping") = "latlong", py::arg("normals_level") = 5,
      py::arg("floor_fraction") = 0.01, py::arg("dead_angle") = 0.0, py::arg("progress") = py::none(),
      R"doc(Irradiance error of a LightSet (or of SH radiance coefficients, the SH reference line) against
the probe's exact ground truth at the 20·4^normals_level icosphere normals, as `iblkit eval` measures
it: an ErrorStats (mean_rel, max_rel, rms_rel, rms_abs, mean_est, mean_gt).)doc");
}

}  // namespace iblpy
