// nearfield/ (submodule iblkit.nearfield): luminaire light-field datasets (iblkit.nearfield/1), their
// simulation from the lab's luminaires, reconstruction and the irradiance on receiver planes.
#include "common.h"

#include <fmt/format.h>

#include "iblkit/core/check.h"
#include "iblkit/nearfield/dataset.h"
#include "iblkit/nearfield/luminaire.h"
#include "iblkit/nearfield/reconstruct.h"
#include "iblkit/nearfield/render.h"
#include "iblkit/nearfield/spotlight.h"

namespace iblpy {

namespace {

namespace nf = ibl::nearfield;

py::list image_list(const std::vector<ibl::Image>& v) {
  py::list l;
  for (const auto& im : v) l.append(to_array(im));
  return l;
}

nf::PlaneDesc plane_desc(double z, double half_extent, int resolution) {
  nf::PlaneDesc pd;
  pd.z = ibl::require_number("z", z, 1e-6, 1e6);
  pd.half_extent = half_extent;
  pd.resolution = resolution;
  if (resolution < 1 || resolution > 8192)
    ibl::fail(ibl::ErrorKind::Value, "resolution must be in 1..8192 (got {})", resolution);
  return pd;
}

}  // namespace

void init_nearfield(py::module_& top) {
  py::module_ m =
      top.def_submodule("nearfield", "Near-field light of luminaires (Goesele et al. 2003, Granier et al. 2003).");

  py::class_<nf::Dataset>(
      m, "Dataset",
      "A luminaire light field in the two-plane setup (the library's nearfield::Dataset, iblkit.nearfield/1).")
      .def_static(
          "load",
          [](const std::string& p) {
            py::gil_scoped_release nogil;
            return nf::read_dataset(p);
          },
          py::arg("path"), "Reads a manifest and its images.")
      .def(
          "save",
          [](const nf::Dataset& d, const std::string& p) {
            py::gil_scoped_release nogil;
            nf::write_dataset(p, d);
          },
          py::arg("path"), "Writes the manifest and its images (STEM_images/ beside it).")
      .def_readonly("name", &nf::Dataset::name)
      .def_readonly("luminaire", &nf::Dataset::luminaire,
                    "The lab luminaire a simulated dataset came from ('' when measured).")
      .def_property_readonly("basis", [](const nf::Dataset& d) { return std::string(nf::basis_name(d.basis)); })
      .def_readonly("spacing", &nf::Dataset::spacing, "h, metres.")
      .def_readonly("filter_width", &nf::Dataset::filter_width)
      .def_readonly("nx", &nf::Dataset::nx)
      .def_readonly("ny", &nf::Dataset::ny)
      .def_readonly("distance", &nf::Dataset::distance, "d between S and M, metres.")
      .def_property_readonly("m_min", [](const nf::Dataset& d) { return py::make_tuple(d.m_min.x, d.m_min.y); })
      .def_property_readonly("m_max", [](const nf::Dataset& d) { return py::make_tuple(d.m_max.x, d.m_max.y); })
      .def_property_readonly(
          "positive", [](const nf::Dataset& d) { return image_list(d.positive); }, "E⁺ images, index j·nx + i.")
      .def_property_readonly(
          "negative", [](const nf::Dataset& d) { return image_list(d.negative); }, "E⁻ images, index j·nx + i.")
      .def(
          "measurement",
          [](const nf::Dataset& d, int i, int j) {
            if (i < 0 || j < 0 || i >= d.nx || j >= d.ny) throw py::index_error("filter position out of range");
            return to_array(d.measurement(i, j));
          },
          py::arg("i"), py::arg("j"), "E_ij = gain·(E⁺ − E⁻) at filter position (i, j).")
      .def(
          "incoming_radiance",
          [](const nf::Dataset& d) {
            std::vector<ibl::Image> e;
            {
              py::gil_scoped_release nogil;
              e = nf::incoming_radiance(d);
            }
            return image_list(e);
          },
          "E'_mn textures of the shift-invariant reconstruction (Eqs. 7–11), index n·nx + m.")
      .def("__len__", &nf::Dataset::count)
      .def("__repr__",
           [](const nf::Dataset& d) { return fmt::format("nearfield.Dataset('{}', {}x{})", d.name, d.nx, d.ny); });

  m.def("luminaires", &nf::luminaire_names, "Names of the lab's virtual luminaires.");

  m.def(
      "simulate",
      [](const std::string& luminaire, py::object grid, const std::string& basis, double spacing, double distance,
         int resolution, double extent, py::object progress) {
        auto lum = nf::make_luminaire(luminaire);
        nf::SimulateDesc d;
        auto g = grid.cast<std::pair<int, int>>();
        d.nx = g.first;
        d.ny = g.second;
        if (d.nx < 1 || d.ny < 1 || d.nx > 64 || d.ny > 64)
          ibl::fail(ibl::ErrorKind::Value, "grid must be in 1..64 per axis");
        d.basis = nf::parse_basis(basis, "basis");
        d.spacing = spacing;
        d.distance = distance;
        d.resolution = resolution;
        d.extent = extent;
        if (resolution < 1 || resolution > 4096) ibl::fail(ibl::ErrorKind::Value, "resolution must be in 1..4096");
        Progress pr(progress);
        nf::Dataset ds;
        {
          py::gil_scoped_release nogil;
          ds = nf::simulate(lum, d, pr.fn());
        }
        pr.rethrow();
        return ds;
      },
      py::arg("luminaire") = "flashlight", py::arg("grid") = py::make_tuple(7, 7), py::arg("basis") = "biquadratic",
      py::arg("spacing") = 0.005, py::arg("distance") = 0.5, py::arg("resolution") = 128, py::arg("extent") = 0.0,
      py::arg("progress") = py::none(),
      "Simulates the acquisition of a lab luminaire, as `iblkit nearfield simulate`: a Dataset.");

  m.def(
      "plane_irradiance",
      [](const nf::Dataset& ds, double z, double half_extent, int resolution) {
        nf::Placement pl;
        pl.position = {0, 0, 0};
        if (half_extent <= 0) half_extent = std::max(std::abs(ds.m_min.x), ds.m_max.x) * z / ds.distance;
        auto pd = plane_desc(z, half_extent, resolution);
        ibl::Image img;
        {
          py::gil_scoped_release nogil;
          auto lights = nf::spotlights(ds, pl, false);
          img = nf::plane_irradiance(lights, pl, pd);
        }
        return to_array(std::move(img));
      },
      py::arg("dataset"), py::arg("z") = 0.5, py::arg("half_extent") = 0.0, py::arg("resolution") = 128,
      R"doc(Irradiance (W/m², RGB) on the plane at distance z along the beam from the dataset's textured
spotlights, as `iblkit nearfield irradiance` (half_extent 0: where the dataset's rays reach).)doc");

  m.def(
      "plane_irradiance_exact",
      [](const std::string& luminaire, double z, double half_extent, int resolution) {
        auto lum = nf::make_luminaire(luminaire);
        auto pd = plane_desc(z, ibl::require_number("half_extent", half_extent, 1e-6, 1e6), resolution);
        ibl::Image img;
        {
          py::gil_scoped_release nogil;
          img = nf::plane_irradiance_exact(lum, pd);
        }
        return to_array(std::move(img));
      },
      py::arg("luminaire"), py::arg("z"), py::arg("half_extent"), py::arg("resolution") = 128,
      "The exact irradiance of a lab luminaire on the same plane.");

  m.def(
      "compare",
      [](py::handle approx, py::handle exact) {
        ibl::Image a = to_image(approx, "compare: approx", 3), e = to_image(exact, "compare: exact", 3);
        if (a.width() != e.width() || a.height() != e.height())
          throw py::value_error("compare: images of different sizes");
        auto s = nf::compare(a, e);
        py::dict d;
        d["rel_rms"] = s.rel_rms;
        d["rel_mean_abs"] = s.rel_mean_abs;
        d["rel_max"] = s.rel_max;
        d["power_ratio"] = s.power_ratio;
        return d;
      },
      py::arg("approx"), py::arg("exact"),
      "Luminance errors of an approximation: rel_rms, rel_mean_abs, rel_max, power_ratio.");
}

}  // namespace iblpy
