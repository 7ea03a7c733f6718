// capture/: HDR merge of a bracket given as numpy arrays (issue 29 §1, docs/capture.md).
#include "common.h"

#include <fmt/format.h>
#include "iblkit/capture/merge.h"
#include "iblkit/capture/response.h"

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
}

}  // namespace iblpy
