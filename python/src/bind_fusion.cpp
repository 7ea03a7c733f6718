// fusion/: probe sets on a proxy (ProbeSet, iblkit.probes/1) and the local map fused at any point.
#include "common.h"

#include <fmt/format.h>

#include "iblkit/core/check.h"
#include "iblkit/fusion/fuse.h"
#include "iblkit/fusion/probe_set.h"

namespace iblpy {

void init_fusion(py::module_& m) {
  using ibl::fusion::LocalMap;
  using ibl::fusion::ProbeSet;
  py::class_<ProbeSet, std::shared_ptr<ProbeSet>>(
      m, "ProbeSet", "Probes with positions and depth maps on a proxy mesh (the library's fusion::ProbeSet).")
      .def_static(
          "load",
          [](const std::string& path, bool use_depth_files, bool write_cache) {
            ibl::fusion::LoadDesc d;
            d.use_depth_files = use_depth_files;
            d.write_cache = write_cache;
            py::gil_scoped_release nogil;
            return std::make_shared<ProbeSet>(ibl::fusion::load_probe_set(path, d));
          },
          py::arg("path"), py::arg("use_depth_files") = true, py::arg("write_cache") = true,
          "Reads an iblkit.probes/1 manifest, its proxy and probes; traces missing depth maps (cached beside the "
          "probes).")
      .def_readonly("manifest", &ProbeSet::manifest)
      .def_readonly("proxy", &ProbeSet::proxy, "The proxy TriMesh.")
      .def_readonly("warnings", &ProbeSet::warnings)
      .def_property_readonly(
          "positions",
          [](const ProbeSet& s) {
            std::vector<ibl::Vec3> p;
            for (const auto& q : s.probes) p.push_back(q.position);
            return vec3_array(p);
          },
          "(N, 3) probe positions.")
      .def(
          "probe_image",
          [](const ProbeSet& s, int i) {
            if (i < 0 || i >= static_cast<int>(s.probes.size())) throw py::index_error("probe index out of range");
            return to_array(s.probes[i].radiance.image);
          },
          py::arg("index"), "Probe `index`'s radiance as an (H, W, 3) array.")
      .def("__len__", [](const ProbeSet& s) { return s.probes.size(); })
      .def("__repr__",
           [](const ProbeSet& s) { return fmt::format("ProbeSet('{}', {} probes)", s.manifest, s.probes.size()); });

  py::class_<LocalMap>(m, "LocalMap", "The environment map fused at a point (the library's fusion::LocalMap).")
      .def_property_readonly("point", [](const LocalMap& l) { return vec3_tuple(l.point); })
      .def_property_readonly(
          "radiance", [](const LocalMap& l) { return to_array(l.radiance.image); }, "(H, W, 3) radiance in `mapping`.")
      .def_property_readonly("mapping",
                             [](const LocalMap& l) { return ibl::sphere::mapping_name(l.radiance.mapping.kind()); })
      .def_property_readonly(
          "depth", [](const LocalMap& l) { return to_array(l.depth, true); },
          "(H, W) distance to the proxy, m (0: left it).")
      .def_property_readonly(
          "coverage", [](const LocalMap& l) { return to_array(l.coverage, true); },
          "(H, W) probes that see each pixel's point.")
      .def_property_readonly(
          "stats",
          [](const LocalMap& l) {
            py::dict d;
            d["fused"] = l.stats.fused;
            d["left_proxy"] = l.stats.left_proxy;
            d["unseen"] = l.stats.unseen;
            d["mean_probes"] = l.stats.mean_probes;
            return d;
          },
          "Shares of the sphere fused, left the proxy and unseen, and the mean probes per fused pixel.")
      .def_readonly("warnings", &LocalMap::warnings);

  m.def(
      "load_probe_set",
      [](const std::string& path) {
        py::gil_scoped_release nogil;
        return std::make_shared<ProbeSet>(ibl::fusion::load_probe_set(path));
      },
      py::arg("path"), "ProbeSet.load(path) with the defaults.");

  m.def(
      "fuse",
      [](const ProbeSet& set, py::handle at, const std::string& mapping, int size, const std::string& blend,
         bool visibility, int samples, double depth_bias, double depth_tolerance, bool check_point,
         py::object progress) {
        ibl::Vec3 x = to_vec3(at, "fuse: at");
        ibl::require_point("fuse point", x);
        ibl::fusion::FuseDesc d;
        d.mapping = ibl::sphere::parse_mapping(mapping, "mapping");
        d.size = size;
        d.blend = ibl::fusion::parse_blend(blend);
        d.visibility = visibility;
        d.samples = samples;
        d.depth_bias = depth_bias;
        d.depth_tolerance = depth_tolerance;
        d.check_point = check_point;
        Progress pr(progress);
        d.progress = pr.fn();
        LocalMap lm;
        {
          py::gil_scoped_release nogil;
          lm = ibl::fusion::fuse(set, x, d);
        }
        pr.rethrow();
        return lm;
      },
      py::arg("probe_set"), py::arg("at"), py::arg("mapping") = "latlong", py::arg("size") = 64,
      py::arg("blend") = "footprint", py::arg("visibility") = true, py::arg("samples") = 1,
      py::arg("depth_bias") = 0.01, py::arg("depth_tolerance") = 0.10, py::arg("check_point") = true,
      py::arg("progress") = py::none(),
      R"doc(The local environment map at `at` fused from the probe set (Pedersen 2008), as `iblkit fuse`:
a LocalMap (radiance, depth, coverage, stats). blend: nearest, angle or footprint; visibility: the
per-probe depth test; size: lat-long height (cube face, disc diameter).)doc");
}

}  // namespace iblpy
