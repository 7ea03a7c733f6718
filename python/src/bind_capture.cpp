// capture/: HDR merge of a bracket given as numpy arrays (issue 29 §1, docs/capture.md).
#include "common.h"

#include <optional>

#include <fmt/format.h>
#include "iblkit/capture/camera_solve.h"
#include "iblkit/capture/merge.h"
#include "iblkit/capture/response.h"

#include "iblkit/core/check.h"
#include "iblkit/core/error.h"

namespace iblpy {

void init_capture(py::module_& m) {
  m.def(
      "hdr_merge",
      [](const std::vector<py::object>& images, const std::vector<double>& exposures, std::string response,
         std::string method, bool align) {
        if (images.size() != exposures.size())
          ibl::fail(ibl::ErrorKind::Value, "hdr_merge: {} images but {} exposures: give one exposure per image",
                    images.size(), exposures.size());
        std::vector<ibl::capture::Frame> frames;
        for (size_t j = 0; j < images.size(); ++j) {
          const std::string what = fmt::format("hdr_merge: images[{}]", j);
          ibl::Image codes = to_image(images[j], what.c_str()).with_channels(3);
          for (size_t i = 0; i < codes.size(); ++i)
            if (!(codes.data()[i] >= 0 && codes.data()[i] <= 1))
              ibl::fail(ibl::ErrorKind::Value, "{}: code value {} outside [0, 1] (divide 8-bit data by 255)", what,
                        codes.data()[i]);
          frames.push_back({std::move(codes), exposures[j], what});
        }
        ibl::capture::MergeDesc d;
        if (!response.empty()) d.response = ibl::capture::response_by_name(response);
        d.method = method;
        d.align = align;
        ibl::capture::MergeReport rep;
        ibl::Image hdr;
        {
          py::gil_scoped_release release;
          hdr = ibl::capture::merge_hdr(frames, d, &rep);
        }
        py::dict report;
        report["response"] = rep.response.kind;
        report["curve"] = to_array([&] {
          ibl::Image c(rep.response.size(), 1, 3);
          for (int i = 0; i < rep.response.size(); ++i)
            for (int ch = 0; ch < 3; ++ch) c.at(i, 0, ch) = static_cast<float>(rep.response.inverse[ch][i]);
          return c;
        }());
        std::vector<std::array<int, 2>> shifts = rep.shifts;
        report["shifts"] = shifts;
        report["saturated_everywhere"] = rep.saturated_everywhere;
        report["black_everywhere"] = rep.black_everywhere;
        report["well_exposed"] = rep.well_exposed;
        report["dynamic_range_stops"] = rep.dynamic_range_stops;
        report["noise"] = rep.noise;
        return py::make_tuple(to_array(std::move(hdr)), report);
      },
      py::arg("images"), py::arg("exposures"), py::arg("response") = "", py::arg("method") = "debevec",
      py::arg("align") = true,
      "HDR image from a bracket: images are (H, W, 3) code values in [0, 1] (8-bit data / 255), exposures the\n"
      "relative exposure of each (t * ISO/100 / N^2). response: '' (recover with `method`: debevec or\n"
      "robertson), 'srgb', 'linear', 'camera' or an iblkit.response/1 file. Returns (hdr, report); report['curve']\n"
      "is the inverse response (1, bins, 3).");

  m.def(
      "camera_solve",
      [](py::object photo, py::object points, const std::string& board, py::handle board_origin, py::handle board_axes,
         double fov, py::object intrinsics, int width, int height) {
        namespace cap = ibl::capture;
        ibl::Image img;
        if (!photo.is_none()) {
          img = to_checked_image(photo, "camera_solve: photo");
          width = img.width();
          height = img.height();
        }
        if (width <= 0 || height <= 0)
          ibl::fail(ibl::ErrorKind::Value, "camera_solve: give the photo, or its width and height with points=");
        if (points.is_none() == board.empty())
          ibl::fail(ibl::ErrorKind::Value, "camera_solve: give either points= or board=");
        ibl::geometry::Camera lens;
        lens.width = width;
        lens.height = height;
        cap::LensMode mode = cap::LensMode::SolveFocal;
        if (fov != 0 && !intrinsics.is_none())
          ibl::fail(ibl::ErrorKind::Value, "camera_solve: fov= and intrinsics= both fix the lens; give one");
        if (fov != 0) {
          lens.fov_y_deg = ibl::require_number("camera_solve: fov", fov, 1e-3, 179);
          mode = cap::LensMode::Fixed;
        } else if (!intrinsics.is_none()) {
          const auto k = intrinsics.cast<ibl::geometry::Camera>();
          if (!k.intrinsics) ibl::fail(ibl::ErrorKind::Value, "camera_solve: intrinsics= has no intrinsics");
          if (k.width != width || k.height != height)
            ibl::fail(ibl::ErrorKind::Value, "camera_solve: intrinsics= is for {}x{}, the photo is {}x{}", k.width,
                      k.height, width, height);
          lens.intrinsics = k.intrinsics;
          lens.distortion = k.distortion;
          lens.fov_y_deg = k.fov_y_deg;
          mode = cap::LensMode::Fixed;
        }
        std::vector<cap::Correspondence> pts;
        bool from_board = !board.empty();
        cap::Board b;
        if (from_board) {
          if (img.width() == 0) ibl::fail(ibl::ErrorKind::Value, "camera_solve: board= needs the photo");
          b = cap::parse_board(board, "camera_solve: board");
          const auto ax = py::cast<std::vector<double>>(board_axes);
          if (ax.size() != 6)
            ibl::fail(ibl::ErrorKind::Value, "camera_solve: board_axes: six numbers ux,uy,uz,vx,vy,vz");
          cap::place_board(b, to_vec3(board_origin, "camera_solve: board_origin"), {ax[0], ax[1], ax[2]},
                           {ax[3], ax[4], ax[5]}, "camera_solve: board_axes");
          std::optional<std::vector<cap::Correspondence>> found;
          {
            py::gil_scoped_release release;
            found = cap::find_board(img, b);
          }
          if (!found)
            ibl::fail(ibl::ErrorKind::Value, "camera_solve: no {} ({}) found in the photo ({})", b.describe(), board,
                      b.find_hint());
          pts = *found;
        } else if (py::isinstance<py::str>(points)) {
          pts = cap::read_points(points.cast<std::string>());
        } else {
          for (py::handle p : points) {
            auto pair = py::reinterpret_borrow<py::sequence>(p);
            if (pair.size() != 2)
              ibl::fail(ibl::ErrorKind::Value, "camera_solve: points: each point is ((u, v), (x, y, z))");
            const auto uv = py::cast<std::vector<double>>(pair[0]);
            if (uv.size() != 2) ibl::fail(ibl::ErrorKind::Value, "camera_solve: points: a pixel is (u, v)");
            pts.push_back({{uv[0], uv[1]}, to_vec3(pair[1], "camera_solve: points world")});
          }
          pts = cap::points_from_json(cap::points_to_json(pts), "camera_solve: points");  // the file's checks
        }
        cap::Solved s;
        {
          py::gil_scoped_release release;
          s = from_board ? cap::solve_board_camera(b, pts, lens, mode) : cap::solve_camera(pts, lens, mode);
        }
        py::dict report;
        report["points"] = pts.size();
        report["coplanar"] = s.coplanar;
        report["lens"] = mode == cap::LensMode::Fixed ? "fixed" : "focal solved";
        report["reprojection_rms_px"] = s.error.rms_px;
        report["reprojection_max_px"] = s.error.max_px;
        report["worst"] = s.error.worst;
        report["dropped"] = s.dropped;
        return py::make_tuple(s.camera, report);
      },
      py::arg("photo") = py::none(), py::kw_only(), py::arg("points") = py::none(), py::arg("board") = "",
      py::arg("board_origin") = py::make_tuple(0, 0, 0), py::arg("board_axes") = py::make_tuple(1, 0, 0, 0, 0, -1),
      py::arg("fov") = 0.0, py::arg("intrinsics") = py::none(), py::arg("width") = 0, py::arg("height") = 0,
      "The camera of a photograph, as `iblkit camera solve` finds it (docs/camera.md): from points= (an\n"
      "iblkit.points/1 file, or [((u, v), (x, y, z)), ...], pixels in continuous coordinates, at least 6) or from a\n"
      "board seen in photo (board='checker:COLSxROWS:SQUARE_M', inner corners, or\n"
      "'charuco:SQXxSQY:SQUARE_M:MARKER_M[:DICT]', squares; placed by board_origin and board_axes; misread ChArUco\n"
      "corners left out, report['dropped']). The lens: fov= (vertical degrees, a pinhole), intrinsics= (a Camera with "
      "intrinsics), or neither\n"
      "(one focal length solved). Returns (Camera, report); report['reprojection_rms_px'] says how well it fits.");
}

}  // namespace iblpy
