// capture/ball.h: probes from photographs of a chrome ball (docs/capture.md, docs/python.md).
#include <optional>
#include <vector>

#include "common.h"
#include "iblkit/capture/ball.h"
#include "iblkit/capture/ball_calibrate.h"
#include "iblkit/core/error.h"

namespace iblpy {

void init_capture_ball(py::module_& m) {
  m.def(
      "find_ball",
      [](py::handle photo) {
        ibl::Image img = to_checked_image(photo, "find_ball: photo");
        ibl::capture::CircleFit f;
        {
          py::gil_scoped_release nogil;
          f = ibl::capture::find_ball(img, "find_ball: photo", "probe_from_ball(balls=…)");
        }
        py::dict d;
        d["ball"] = py::make_tuple(f.circle.cx, f.circle.cy, f.circle.r);
        d["residual_px"] = f.residual_px;
        d["edge_points"] = f.edge_points;
        d["coverage"] = f.coverage;
        return d;
      },
      py::arg("photo"),
      R"doc(Finds a chrome ball's silhouette in a photograph (H, W, 3): a circle fitted to its edge.
Returns {"ball": (cx, cy, r), "residual_px", "edge_points", "coverage"} in continuous pixel
coordinates (the image spans [0, W] × [0, H]). Raises InvalidValue when no ball is found.)doc");

  m.def(
      "probe_from_ball",
      [](py::list photos, py::object balls, double distance, double angle,
         std::optional<std::vector<double>> reflectance, const std::string& fresnel, const std::string& mapping,
         int size, int samples, double rotate, double exclude) {
        if (photos.size() < 1 || photos.size() > 2)
          ibl::fail(ibl::ErrorKind::Value, "probe_from_ball: give one or two photographs, got {}", photos.size());
        std::vector<ibl::capture::BallView> views;
        for (size_t i = 0; i < photos.size(); ++i) {
          ibl::capture::BallView v;
          v.photo = to_checked_image(photos[i], "probe_from_ball: photos[i]");
          v.name = "photos[" + std::to_string(i) + "]";
          v.distance = distance;
          v.angle_deg = i == 0 ? 0 : angle;
          views.push_back(std::move(v));
        }
        if (balls.is_none()) {
          py::gil_scoped_release nogil;
          for (auto& v : views) v.ball = ibl::capture::find_ball(v.photo, v.name, "balls=").circle;
        } else {
          auto list = balls.cast<std::vector<std::vector<double>>>();
          if (list.size() != views.size())
            ibl::fail(ibl::ErrorKind::Value, "probe_from_ball: balls needs one (cx, cy, r) per photograph");
          for (size_t i = 0; i < list.size(); ++i) {
            if (list[i].size() != 3) ibl::fail(ibl::ErrorKind::Value, "probe_from_ball: a ball is (cx, cy, r)");
            views[i].ball = {list[i][0], list[i][1], list[i][2]};
          }
        }
        ibl::capture::FromBallDesc d;
        d.mapping = ibl::sphere::parse_mapping(mapping, "mapping");
        d.size = size;
        d.samples = samples;
        d.exclude_deg = exclude;
        d.rotation = ibl::Mat3::rotation({0, 1, 0}, rotate * ibl::kPi / 180);
        ibl::capture::parse_fresnel(fresnel, &d.reflectance, "fresnel");
        if (reflectance) {
          const auto& r = *reflectance;
          if (r.size() != 1 && r.size() != 3)
            ibl::fail(ibl::ErrorKind::Value, "probe_from_ball: reflectance is r or (r, g, b)");
          d.reflectance.r0 = r.size() == 1 ? ibl::Vec3{r[0], r[0], r[0]} : ibl::Vec3{r[0], r[1], r[2]};
        }
        ibl::capture::FromBallResult res;
        {
          py::gil_scoped_release nogil;
          res = ibl::capture::probe_from_ball(views, d);
        }
        return py::make_tuple(to_array(std::move(res.probe.image)), to_array(std::move(res.weights), true));
      },
      py::arg("photos"), py::arg("balls") = py::none(), py::arg("distance") = 0.0, py::arg("angle") = 90.0,
      py::arg("reflectance") = py::none(), py::arg("fresnel") = "chrome", py::arg("mapping") = "latlong",
      py::arg("size") = 256, py::arg("samples") = 2, py::arg("rotate") = 0.0, py::arg("exclude") = 40.0,
      R"doc(A probe from one or two linear photographs of a chrome ball, as `iblkit probe from-ball`.

photos: [(H, W, 3) float arrays]; balls: [(cx, cy, r)] per photograph (None: found by find_ball);
distance: camera to ball centre in ball radii (0: orthographic); angle: where the second camera stood,
degrees about +Y; reflectance: r or (r, g, b) at normal incidence (None: the metal's own); fresnel:
"chrome", "steel", "none" or "n,k". Returns (probe (H, W, 4) RGBA — alpha 0 where no view sees —,
weights (H, W): the first photograph's share).)doc");

  m.def(
      "calibrate_ball",
      [](py::handle photo, std::vector<double> light_in_ball, py::handle direct, std::vector<double> light,
         std::optional<std::vector<double>> ball, double distance, const std::string& fresnel, double plateau) {
        auto box = [](const std::vector<double>& b, const char* what) {
          if (b.size() != 4) ibl::fail(ibl::ErrorKind::Value, "calibrate_ball: {} is (x, y, w, h) in pixels", what);
          return ibl::capture::PixelBox{b[0], b[1], b[2], b[3]};
        };
        ibl::capture::BallView v;
        v.photo = to_checked_image(photo, "calibrate_ball: photo");
        v.name = "photo";
        v.distance = distance;
        ibl::Image d = to_checked_image(direct, "calibrate_ball: direct");
        ibl::capture::BallReflectance metal;
        ibl::capture::parse_fresnel(fresnel, &metal, "fresnel");
        ibl::capture::ReflectanceFit f;
        {
          py::gil_scoped_release nogil;
          if (ball) {
            if (ball->size() != 3) ibl::fail(ibl::ErrorKind::Value, "calibrate_ball: a ball is (cx, cy, r)");
            v.ball = {(*ball)[0], (*ball)[1], (*ball)[2]};
          } else {
            v.ball = ibl::capture::find_ball(v.photo, v.name, "ball=").circle;
          }
          f = ibl::capture::calibrate_reflectance(v, metal, box(light_in_ball, "light_in_ball"), d, box(light, "light"),
                                                  plateau, "calibrate_ball");
        }
        py::dict r;
        r["reflectance"] = py::make_tuple(f.r0.x, f.r0.y, f.r0.z);
        r["light"] = py::make_tuple(f.light.x, f.light.y, f.light.z);
        r["incidence_deg"] = py::make_tuple(f.incidence_min_deg, f.incidence_max_deg);
        r["ball_pixels"] = f.ball_pixels;
        r["direct_pixels"] = f.direct_pixels;
        r["spread"] = f.spread;
        r["ball"] = py::make_tuple(v.ball.cx, v.ball.cy, v.ball.r);
        return r;
      },
      py::arg("photo"), py::arg("light_in_ball"), py::arg("direct"), py::arg("light"), py::arg("ball") = py::none(),
      py::arg("distance") = 0.0, py::arg("fresnel") = "chrome", py::arg("plateau") = 0.8,
      R"doc(The chrome ball's reflectance from a light seen in the ball and directly, as `iblkit probe calibrate`.

photo: the ball's linear photograph (H, W, 3); light_in_ball: (x, y, w, h) around the light's reflection; direct:
a linear image of the light in the same units (the same camera and exposure); light: (x, y, w, h) around it;
ball: (cx, cy, r) (None: found); distance: camera to ball centre in ball radii (0: orthographic); fresnel: the
metal's rise taken out. Returns {"reflectance": (r, g, b) at normal incidence — probe_from_ball's reflectance —,
"light", "incidence_deg", "ball_pixels", "direct_pixels", "spread", "ball"}.)doc");
}

}  // namespace iblpy
