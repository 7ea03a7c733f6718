// ilf/ (submodule iblkit.ilf): the SH grid type (SHGrid, the library's ilf::SHGrid) and the ILF build
// from a probe sequence file or from probes in memory, with its report.
#include "common.h"

#include <filesystem>
#include <random>

#include <fmt/format.h>

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/ilf/adaptive.h"
#include "iblkit/ilf/build.h"
#include "iblkit/ilf/sequence.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/io/image_io.h"
#include "iblkit/sh/basis.h"

namespace iblpy {

namespace {

namespace fs = std::filesystem;
using ibl::ilf::SHGrid;

py::array coefficients_view(py::object self) {
  SHGrid& g = self.cast<SHGrid&>();
  const auto& gd = g.grid();
  const py::ssize_t K = g.coeff_count(), f = sizeof(float);
  return py::array_t<float>({py::ssize_t(gd.nz), py::ssize_t(gd.ny), py::ssize_t(gd.nx), K, py::ssize_t(3)},
                            {gd.ny * gd.nx * K * 3 * f, gd.nx * K * 3 * f, K * 3 * f, 3 * f, f}, g.data().data(), self);
}

SHGrid make_grid(py::handle coefficients, py::handle lo, py::handle hi) {
  py::array a = py::array::ensure(coefficients);
  if (!a || a.dtype().kind() != 'f')
    throw py::type_error("SHGrid: coefficients must be a float array (nz, ny, nx, K, 3)");
  if (a.ndim() != 5 || a.shape(4) != 3)
    throw py::value_error(
        fmt::format("SHGrid: coefficients must have shape (nz, ny, nx, K, 3), got ndim {}", a.ndim()));
  int nz = int(a.shape(0)), ny = int(a.shape(1)), nx = int(a.shape(2)), K = int(a.shape(3));
  int bands = static_cast<int>(std::lround(std::sqrt(double(K))));
  if (bands * bands != K || bands < 1 || bands > ibl::sh::kMaxBands)
    throw py::value_error(fmt::format("SHGrid: K = {} is not bands² with bands in 1..{}", K, ibl::sh::kMaxBands));
  if (nx < 2 || ny < 2 || nz < 2) throw py::value_error("SHGrid: at least 2 grid points per axis");
  ibl::ilf::GridDesc gd;
  gd.nx = nx;
  gd.ny = ny;
  gd.nz = nz;
  gd.volume = {to_vec3(lo, "SHGrid: min"), to_vec3(hi, "SHGrid: max")};
  ibl::require_box("SHGrid volume", gd.volume.min, gd.volume.max, true);
  SHGrid g(gd, bands);
  auto f = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
  std::copy(f.data(), f.data() + f.size(), g.data().begin());
  for (float v : g.data())
    if (!std::isfinite(v)) ibl::fail(ibl::ErrorKind::Value, "SHGrid: coefficients must be finite");
  return g;
}

std::vector<ibl::Vec3> points_arg(py::handle obj, const char* what) {
  auto p = to_vec3s(obj, what);
  for (auto& q : p) ibl::require_point(what, q);
  return p;
}
std::vector<ibl::Vec3> dirs_arg(py::handle obj, const char* what, size_t n) {
  auto d = to_vec3s(obj, what);
  if (d.size() == 1 && n > 1) d.assign(n, d[0]);
  if (d.size() != n) throw py::value_error(fmt::format("{}: {} rows for {} points", what, d.size(), n));
  for (auto& q : d) q = ibl::require_direction(what, q);
  return d;
}

py::dict report_dict(const ibl::ilf::BuildReport& r) {
  py::dict d;
  d["probes_in"] = r.probes_in;
  d["probes_used"] = r.probes_used;
  d["skipped"] = r.skipped;
  d["subsampled_out"] = r.subsampled_out;
  d["skip_reasons"] = r.skip_reasons;
  d["buckets"] = r.buckets;
  d["blocks"] = r.blocks;
  d["octahedral"] = r.octahedral;
  d["samples"] = r.samples;
  d["uncovered"] = r.uncovered;
  d["fraction_uncovered"] = r.fraction_uncovered;
  d["buckets_reused"] = r.buckets_reused;
  d["t_subsample"] = r.t_subsample;
  d["t_sort"] = r.t_sort;
  d["t_project"] = r.t_project;
  d["t_accumulate"] = r.t_accumulate;
  d["t_total"] = r.t_total;
  d["gemm_flops"] = r.gemm_flops;
  d["kernel_cells"] = r.kernel_cells;
  if (r.choice) {
    py::list trials;
    for (const auto& t : r.choice->trials) {
      py::dict td;
      td["kernel"] = t.kernel;
      td["cv_error"] = t.cv_error;
      if (r.choice->focus) td["focus_error"] = t.focus_error;
      trials.append(td);
    }
    py::dict c;
    c["kernel"] = r.choice->kernel;
    c["trials"] = trials;
    if (r.choice->focus) {
      c["focus_error"] = r.choice->trials[r.choice->chosen].focus_error;
      c["focus_sigma"] = r.choice->focus_sigma;
      c["focus_weight"] = r.choice->focus_weight;
      c["volume_kernel"] = r.choice->volume_kernel;
    }
    d["choice"] = c;
  }
  return d;
}

// A folder that is removed with this object (the frames and buckets of a build from arrays).
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& parent) {
    fs::path base = parent.empty() ? fs::temp_directory_path() : fs::path(parent);
    std::random_device rd;
    for (int i = 0; i < 100 && path.empty(); ++i) {
      fs::path p = base / fmt::format("iblkit-ilf-{:016x}", (uint64_t(rd()) << 32) ^ rd());
      std::error_code ec;
      if (fs::create_directories(p, ec)) path = p;
    }
    if (path.empty()) ibl::fail(ibl::ErrorKind::Io, "ilf.build: cannot create a temporary folder in {}", base.string());
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

}  // namespace

// Also used by bind_render.cpp and bind_augment.cpp.
const SHGrid& shgrid_arg(py::handle obj) { return obj.cast<const SHGrid&>(); }

void init_ilf(py::module_& top) {
  py::module_ m = top.def_submodule("ilf", "Incident light fields: probe sequences → SH grids (Löw et al. 2009).");

  py::class_<SHGrid>(m, "SHGrid",
                     R"doc(SH coefficients of the incident radiance at the points of a regular grid (the library's
ilf::SHGrid, the .shgrid file). `coefficients` is a writable (nz, ny, nx, K, 3) float32 view of the
grid's storage (no copy); point (i, j, k) sits at min + (max − min)·(i/(nx−1), j/(ny−1), k/(nz−1)).)doc")
      .def(py::init(&make_grid), py::arg("coefficients"), py::arg("min"), py::arg("max"),
           "From a (nz, ny, nx, K, 3) array (copied) and the volume's corners.")
      .def_property_readonly("coefficients", &coefficients_view, "(nz, ny, nx, K, 3) float32 view of the coefficients.")
      .def_property_readonly(
          "min", [](const SHGrid& g) { return vec3_tuple(g.grid().volume.min); }, "Volume corner (x, y, z), metres.")
      .def_property_readonly(
          "max", [](const SHGrid& g) { return vec3_tuple(g.grid().volume.max); }, "Opposite corner, metres.")
      .def_property_readonly(
          "resolution", [](const SHGrid& g) { return py::make_tuple(g.grid().nx, g.grid().ny, g.grid().nz); },
          "(nx, ny, nz) grid points.")
      .def_property_readonly("bands", &SHGrid::bands, "SH bands (K = bands²).")
      .def("__repr__",
           [](const SHGrid& g) {
             return fmt::format("SHGrid({}x{}x{}, bands={})", g.grid().nx, g.grid().ny, g.grid().nz, g.bands());
           })
      .def(
          "eval",
          [](const SHGrid& g, py::handle points) {
            auto p = points_arg(points, "SHGrid.eval: points");
            const py::ssize_t K = g.coeff_count();
            py::array_t<double> out({static_cast<py::ssize_t>(p.size()), K, py::ssize_t(3)});
            double* o = out.mutable_data();
            {
              py::gil_scoped_release nogil;
              for (size_t i = 0; i < p.size(); ++i) {
                auto c = g.coeffs_at(p[i]);
                for (py::ssize_t k = 0; k < K; ++k) {
                  o[(i * K + k) * 3] = c.c[k].x;
                  o[(i * K + k) * 3 + 1] = c.c[k].y;
                  o[(i * K + k) * 3 + 2] = c.c[k].z;
                }
              }
            }
            return out;
          },
          py::arg("points"),
          "Trilinearly interpolated coefficients at each point ((N, 3), clamped to the volume): (N, K, 3).")
      .def(
          "coeffs_at",
          [](const SHGrid& g, py::handle p) { return g.coeffs_at(points_arg(p, "SHGrid.coeffs_at: point").at(0)); },
          py::arg("point"), "The interpolated coefficients at one point as SHCoeffs.")
      .def(
          "irradiance",
          [](const SHGrid& g, py::handle points, py::handle normals) {
            auto p = points_arg(points, "SHGrid.irradiance: points");
            auto n = dirs_arg(normals, "SHGrid.irradiance: normals", p.size());
            std::vector<ibl::Vec3> e(p.size());
            {
              py::gil_scoped_release nogil;
              for (size_t i = 0; i < p.size(); ++i) e[i] = g.irradiance(p[i], n[i]);
            }
            return vec3_array(e);
          },
          py::arg("points"), py::arg("normals"),
          "Irradiance E(p, n), W/m², at each point and normal (one normal for all, or one each).")
      .def(
          "radiance",
          [](const SHGrid& g, py::handle points, py::handle dirs) {
            auto p = points_arg(points, "SHGrid.radiance: points");
            auto d = dirs_arg(dirs, "SHGrid.radiance: directions", p.size());
            std::vector<ibl::Vec3> e(p.size());
            for (size_t i = 0; i < p.size(); ++i) e[i] = g.radiance(p[i], d[i]);
            return vec3_array(e);
          },
          py::arg("points"), py::arg("directions"), "Band-limited radiance L(p, ω) at each point and direction.")
      .def(
          "glossy",
          [](const SHGrid& g, py::handle points, py::handle dirs, double exponent) {
            auto p = points_arg(points, "SHGrid.glossy: points");
            auto d = dirs_arg(dirs, "SHGrid.glossy: directions", p.size());
            ibl::require_number("SHGrid.glossy: exponent", exponent, 0, 1e6);
            std::vector<ibl::Vec3> e(p.size());
            for (size_t i = 0; i < p.size(); ++i) e[i] = g.glossy(p[i], d[i], exponent);
            return vec3_array(e);
          },
          py::arg("points"), py::arg("directions"), py::arg("exponent"),
          "Normalised Phong-lobe response around reflection directions r (Löw et al. §4).")
      .def(
          "save", [](const SHGrid& g, const std::string& p) { ibl::ilf::write_shgrid(p, g); }, py::arg("path"),
          "Writes a .shgrid file (atomically).")
      .def_static(
          "load", [](const std::string& p) { return ibl::ilf::read_shgrid(p); }, py::arg("path"),
          "Reads a .shgrid file.");

  using ibl::ilf::AdaptiveGrid;
  py::class_<AdaptiveGrid>(m, "AdaptiveGrid",
                           R"doc(An adaptive SH grid (the library's ilf::AdaptiveGrid, the .shtree file): a dense grid's
coefficients kept at full resolution only where coarser levels miss them by more than the tolerance
(docs/ilf.md, "Adaptive storage"). Made by `ilf.adapt(grid, tolerance)`.)doc")
      .def_property_readonly(
          "resolution", [](const AdaptiveGrid& t) { return py::make_tuple(t.grid().nx, t.grid().ny, t.grid().nz); },
          "(nx, ny, nz) points of the fine grid (level 0).")
      .def_property_readonly(
          "min", [](const AdaptiveGrid& t) { return vec3_tuple(t.grid().volume.min); },
          "Volume corner (x, y, z), metres.")
      .def_property_readonly(
          "max", [](const AdaptiveGrid& t) { return vec3_tuple(t.grid().volume.max); }, "Opposite corner, metres.")
      .def_property_readonly("bands", &AdaptiveGrid::bands, "SH bands (K = bands²).")
      .def_property_readonly("levels", &AdaptiveGrid::levels,
                             "Levels, 0 (the fine grid) to the top (2 points per axis).")
      .def_property_readonly("brick", &AdaptiveGrid::brick, "Points per brick axis.")
      .def_property_readonly("tolerance", &AdaptiveGrid::tolerance, "The tolerance it was made with (× rms).")
      .def_property_readonly("rms", &AdaptiveGrid::rms, "RMS over the fine points of the coefficient vector's L2 norm.")
      .def_property_readonly("stored_points", &AdaptiveGrid::stored_points, "Points stored over all levels.")
      .def_property_readonly("file_bytes", &AdaptiveGrid::file_bytes, "Bytes of its .shtree file.")
      .def("__repr__",
           [](const AdaptiveGrid& t) {
             return fmt::format("AdaptiveGrid({}x{}x{}, bands={}, {} points stored)", t.grid().nx, t.grid().ny,
                                t.grid().nz, t.bands(), t.stored_points());
           })
      .def(
          "eval",
          [](const AdaptiveGrid& t, py::handle points) {
            auto p = points_arg(points, "AdaptiveGrid.eval: points");
            const py::ssize_t K = t.coeff_count();
            py::array_t<double> out({static_cast<py::ssize_t>(p.size()), K, py::ssize_t(3)});
            double* o = out.mutable_data();
            {
              py::gil_scoped_release nogil;
              for (size_t i = 0; i < p.size(); ++i) {
                auto c = t.coeffs_at(p[i]);
                for (py::ssize_t k = 0; k < K; ++k) {
                  o[(i * K + k) * 3] = c.c[k].x;
                  o[(i * K + k) * 3 + 1] = c.c[k].y;
                  o[(i * K + k) * 3 + 2] = c.c[k].z;
                }
              }
            }
            return out;
          },
          py::arg("points"), "Coefficients (N, K, 3) at N points: the tree's own lookup.")
      .def(
          "level_at",
          [](const AdaptiveGrid& t, py::handle points) {
            auto p = points_arg(points, "AdaptiveGrid.level_at: points");
            py::array_t<int> out(static_cast<py::ssize_t>(p.size()));
            for (size_t i = 0; i < p.size(); ++i) out.mutable_data()[i] = t.level_at(p[i]);
            return out;
          },
          py::arg("points"), "The level that answers at each point (0: the fine grid's resolution).")
      .def(
          "to_dense",
          [](const AdaptiveGrid& t, py::object grid) {
            int n[3] = {t.grid().nx, t.grid().ny, t.grid().nz};
            if (!grid.is_none()) {
              if (py::isinstance<py::int_>(grid)) {
                n[0] = n[1] = n[2] = grid.cast<int>();
              } else {
                auto g = grid.cast<std::vector<int>>();
                if (g.size() != 3) throw py::value_error("AdaptiveGrid.to_dense: grid must be n or (nx, ny, nz)");
                n[0] = g[0];
                n[1] = g[1];
                n[2] = g[2];
              }
            }
            py::gil_scoped_release nogil;
            return t.to_dense(n[0], n[1], n[2]);
          },
          py::arg("grid") = py::none(),
          "The dense SHGrid of n or (nx, ny, nz) points (default: the fine grid's), each looked up.")
      .def(
          "save", [](const AdaptiveGrid& t, const std::string& p) { ibl::ilf::write_adaptive(p, t); }, py::arg("path"),
          "Writes a .shtree file (atomically).")
      .def_static(
          "load", [](const std::string& p) { return ibl::ilf::read_adaptive(p); }, py::arg("path"),
          "Reads a .shtree file.");

  m.def(
      "adapt",
      [](const SHGrid& g, double tolerance, int brick) {
        py::gil_scoped_release nogil;
        return ibl::ilf::make_adaptive(g, {.tolerance = tolerance, .brick = brick});
      },
      py::arg("grid"), py::arg("tolerance") = ibl::ilf::AdaptDesc{}.tolerance,
      py::arg("brick") = ibl::ilf::AdaptDesc{}.brick,
      "The AdaptiveGrid of a dense SHGrid: within tolerance × rms of its lookup everywhere (`iblkit ilf adapt`).");

  m.def(
      "build",
      [](py::object source, py::object positions, py::object grid, int bands, py::object volume,
         const std::string& mapping, double dead_angle, py::object rotation, const std::string& repair,
         py::object kernel_cells, double raster_cells, py::object directions, const std::string& memory, bool skip_bad,
         bool sanitize, py::object subsample, const std::string& work_dir, py::object progress, py::object focus) {
        ibl::ilf::BuildDesc bd;
        // grid: n or (nx, ny, nz)
        if (py::isinstance<py::int_>(grid)) {
          bd.nx = bd.ny = bd.nz = grid.cast<int>();
        } else {
          auto g = grid.cast<std::vector<int>>();
          if (g.size() != 3) throw py::value_error("ilf.build: grid must be n or (nx, ny, nz)");
          bd.nx = g[0];
          bd.ny = g[1];
          bd.nz = g[2];
        }
        bd.bands = bands;
        if (!volume.is_none()) {
          auto v = volume.cast<std::vector<py::object>>();
          if (v.size() != 2) throw py::value_error("ilf.build: volume must be (min, max)");
          bd.volume = ibl::ilf::Box{to_vec3(v[0], "ilf.build: volume min"), to_vec3(v[1], "ilf.build: volume max")};
        }
        bd.project.repair = ibl::ilf::parse_repair(repair);
        if (py::isinstance<py::str>(kernel_cells)) {
          if (kernel_cells.cast<std::string>() != "auto")
            throw py::value_error("ilf.build: kernel_cells must be a number of grid cells or 'auto'");
          bd.auto_kernel = true;  // cross-validated among 1.5 … 4 cells (`ilf build --kernel auto`)
        } else {
          bd.project.kernel_cells = kernel_cells.cast<double>();
        }
        if (!focus.is_none()) {
          auto f = focus.cast<std::vector<double>>();
          if (f.size() != 3 && f.size() != 4)
            throw py::value_error("ilf.build: focus must be (x, y, z) or (x, y, z, radius)");
          bd.focus = ibl::ilf::Focus{{f[0], f[1], f[2]}, f.size() == 4 ? f[3] : 0.0};
          if (!bd.auto_kernel)
            throw py::value_error("ilf.build: focus chooses the kernel for a neighbourhood: give kernel_cells='auto'");
        }
        bd.project.raster_cells = raster_cells;
        if (directions.is_none() || (py::isinstance<py::str>(directions) && directions.cast<std::string>() == "auto")) {
          bd.buckets.octahedral = -1;
        } else if (py::isinstance<py::str>(directions) && directions.cast<std::string>() == "pixel") {
          bd.buckets.octahedral = 0;
        } else {
          int n = directions.cast<int>();
          if (n < 2 || n > 1024)
            ibl::fail(ibl::ErrorKind::Value, "ilf.build: directions must be 'auto', 'pixel' or N in [2, 1024]");
          bd.buckets.octahedral = n;
        }
        {  // memory: bytes, or "2G", "512M"
          double mult = 1;
          std::string s = memory;
          if (!s.empty() && (s.back() == 'G' || s.back() == 'g')) {
            mult = 1 << 30;
            s.pop_back();
          } else if (!s.empty() && (s.back() == 'M' || s.back() == 'm')) {
            mult = 1 << 20;
            s.pop_back();
          }
          double v = 0;
          try {
            v = std::stod(s);
          } catch (...) {
            ibl::fail(ibl::ErrorKind::Value, "ilf.build: memory '{}': expected bytes, or e.g. 512M, 2G", memory);
          }
          if (!(v * mult >= (64 << 20))) ibl::fail(ibl::ErrorKind::Value, "ilf.build: memory '{}' below 64M", memory);
          bd.buckets.memory_bytes = static_cast<size_t>(v * mult);
        }
        bd.buckets.skip_bad = skip_bad;
        bd.buckets.sanitize = sanitize;
        if (!subsample.is_none()) {
          auto t = subsample.cast<std::pair<double, double>>();
          bd.subsample = ibl::ilf::SubsampleDesc{t.first, t.second, skip_bad};
        }

        ibl::ilf::Sequence seq;
        ibl::ilf::SequenceReport srep;
        std::optional<TempDir> tmp;
        if (py::isinstance<py::str>(source) ||
            py::isinstance(source, py::module_::import("pathlib").attr("PurePath"))) {
          if (!positions.is_none())
            throw py::value_error("ilf.build: positions go with probe images, not with a sequence file");
          std::string path = py::str(source);
          ibl::ilf::SequenceReadDesc rd;
          rd.skip_bad = skip_bad;
          seq = ibl::ilf::read_sequence(path, rd, &srep);
          bd.buckets.dir = work_dir.empty() ? path + ".buckets" : work_dir;
        } else {
          // Probes in memory: written once as float32 PFM frames (lossless) with a manifest into a
          // temporary folder, which also holds the buckets; removed when the build returns.
          if (positions.is_none()) throw py::value_error("ilf.build: probe images need positions=(N, 3)");
          auto pos = to_vec3s(positions, "ilf.build: positions");
          size_t n = py::len(source);
          if (n != pos.size())
            throw py::value_error(fmt::format("ilf.build: {} probe images but {} positions", n, pos.size()));
          if (n < 1) throw py::value_error("ilf.build: no probes");
          tmp.emplace(work_dir);
          fs::create_directories(tmp->path / "frames");
          seq.manifest = (tmp->path / "sequence.json").string();
          if (!rotation.is_none()) seq.rotation = to_mat3(rotation, "ilf.build: rotation");
          seq.dead_angle_deg = dead_angle;
          int w0 = 0, h0 = 0;
          Progress wr(progress);
          for (size_t i = 0; i < n; ++i) {
            ibl::Image img = to_image(py::object(source[py::int_(i)]), "ilf.build: probe image");
            if (i == 0) {
              w0 = img.width();
              h0 = img.height();
              seq.mapping = mapping_of(mapping, w0, h0, dead_angle).kind();
            } else if (img.width() != w0 || img.height() != h0) {
              ibl::fail(ibl::ErrorKind::Value, "ilf.build: probe {} is {}x{}, probe 0 {}x{}", i, img.width(),
                        img.height(), w0, h0);
            }
            ibl::require_point(fmt::format("ilf.build: probe {} position", i), pos[i]);
            std::string file = (tmp->path / "frames" / fmt::format("{:06d}.pfm", i)).string();
            {
              py::gil_scoped_release nogil;
              ibl::io::write_image(file, img.channels() == 3 ? img : img.with_channels(3));
            }
            seq.probes.push_back({file, pos[i], ""});
            ibl::report(wr.fn(), "write frames", double(i + 1) / n);
          }
          wr.rethrow();
          ibl::Vec3 lo = pos[0], hi = pos[0];
          for (auto p : pos)
            for (int a = 0; a < 3; ++a) {
              lo[a] = std::min(lo[a], p[a]);
              hi[a] = std::max(hi[a], p[a]);
            }
          seq.volume = {lo, hi};
          ibl::ilf::write_sequence(seq.manifest, seq);
          ibl::ilf::SequenceReadDesc rd;
          rd.skip_bad = skip_bad;
          seq = ibl::ilf::read_sequence(seq.manifest, rd, &srep);  // the file path's checks, the same sequence
          bd.buckets.dir = (tmp->path / "buckets").string();
          bd.buckets.reuse = false;
        }
        Progress pr(progress);
        ibl::ilf::BuildReport rep;
        SHGrid g;
        {
          py::gil_scoped_release nogil;
          g = ibl::ilf::build_shgrid(seq, bd, pr.fn(), &rep);
        }
        pr.rethrow();
        rep.skipped += srep.skipped;
        for (auto& r : srep.reasons) rep.skip_reasons.insert(rep.skip_reasons.begin(), r);
        return py::make_tuple(std::move(g), report_dict(rep));
      },
      py::arg("source"), py::arg("positions") = py::none(), py::arg("grid") = ibl::ilf::BuildDesc{}.nx,
      py::arg("bands") = ibl::ilf::BuildDesc{}.bands, py::arg("volume") = py::none(), py::arg("mapping") = "auto",
      py::arg("dead_angle") = 0.0, py::arg("rotation") = py::none(), py::arg("repair") = "mip",
      py::arg("kernel_cells") = ibl::ilf::ProjectDesc{}.kernel_cells,
      py::arg("raster_cells") = ibl::ilf::ProjectDesc{}.raster_cells, py::arg("directions") = "auto",
      py::arg("memory") = "2G", py::arg("skip_bad") = false, py::arg("sanitize") = false,
      py::arg("subsample") = py::none(), py::arg("work_dir") = "", py::arg("progress") = py::none(),
      py::arg("focus") = py::none(),
      R"doc(Builds an SH grid from a probe sequence, as `iblkit ilf build`; returns (SHGrid, report dict).

source: an iblkit.sequence/1 manifest path (its buckets go to work_dir, default PATH.buckets, and are
reused by a re-run), or N probe images — an (N, H, W, C) array or a list of (H, W, C) arrays — with
positions=(N, 3) capture positions (then `mapping` ("auto": from the shape), `dead_angle` and
`rotation` (probe frame → world) describe the frames; the volume defaults to the positions' bounds;
frames and buckets live in a temporary folder under work_dir, default the system's, removed after).
grid: n or (nx, ny, nz); bands 1..10; volume: (min, max); repair: mip, pullpush or none;
kernel_cells, raster_cells: the projection's kernel and raster in grid cells (kernel_cells="auto": chosen by
5-fold cross-validation among 1.5 … 4, the report's "choice"; with focus=(x, y, z[, radius]) for the neighbourhood
of an object there, `ilf build --focus`); directions: "auto",
"pixel" or N (N×N octahedral buckets); memory: the build's budget ("2G"); subsample: (threshold,
max_distance) to drop redundant probes first. Releases the GIL; progress(stage, fraction).
The report holds the probe counts, buckets, samples, uncovered share and the stage times (seconds).)doc");
}

}  // namespace iblpy
