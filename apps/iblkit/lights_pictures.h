// Pictures for `iblkit lights`, `iblkit eval` and the demo: the paper's Figure 4 (error vs. number of
// lights), the probe with every light and its region marked, and an irradiance comparison.
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/lights/light_set.h"
#include "iblkit/sphere/envmap.h"

namespace iblcli {

struct ErrorCurve {
  std::string name;          // legend text (a method)
  std::vector<int> counts;   // N
  std::vector<double> mean;  // mean relative error (fraction) at each N
  std::vector<double> max;   // max relative error (fraction) at each N
};

struct ErrorPlotDesc {
  std::string title;                         // drawn above both panels
  double reference_mean = -1;                // a horizontal reference line (3-band SH) on the mean panel; < 0: none
  double reference_max = -1;                 // the same on the max panel
  std::string reference_name = "3-band SH";  // legend text of the reference line
  int width = 1000, height = 420;            // size of the picture in pixels
};

// Two panels (mean and max error in percent against N, log-x), one curve per method.
ibl::Image error_plot(const std::vector<ErrorCurve>& curves, const ErrorPlotDesc& desc);

// The probe (tone mapped, lat-long) with each light's region outlined and each light marked; the
// first `numbered` lights (shadow-map priority) carry their rank.
ibl::Image light_overlay(const ibl::sphere::EnvMap& env, const ibl::lights::LightSet& set, int width = 1024,
                         int numbered = 8);

// Lat-long pictures of irradiance over the sphere of normals: ground truth, the light set's, and the
// relative error (0 → 50%+ as a colour ramp), side by side with captions.
ibl::Image irradiance_comparison(const ibl::sphere::EnvMap& env, const ibl::lights::LightSet& set, int width = 256);

}  // namespace iblcli
