// What every binding file shares (docs/python.md): numpy ↔ library conversions at the boundary, the
// progress callback, the translation of ibl::Error into Python exceptions.
//
// Conventions. Images are float32 arrays (H, W, C); arrays the module returns own the library's
// Image (no copy: the Image moves into a capsule that is the array's base). Inputs of any float dtype,
// any strides and C = 1..4 are accepted; wrong dtypes raise TypeError, wrong shapes ValueError. Points
// and directions are (N, 3) or (3,) float arrays (float64 inside, as the library's Vec3).
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/core/vec.h"
#include "iblkit/sphere/envmap.h"
#include "iblkit/sphere/mapping.h"

namespace iblpy {

namespace py = pybind11;

// ---- images -------------------------------------------------------------------------------------

// The image as an (H, W, C) float32 array that owns it (one channel stays (H, W, 1) unless `squeeze`).
py::array to_array(ibl::Image img, bool squeeze = false);

// A float32 array with C-contiguous pixels: `obj` itself when it already is one, else a converted
// copy. TypeError for a non-numeric or complex dtype or a non-array; ValueError unless the shape is
// (H, W) or (H, W, C) with 1 ≤ C ≤ 4 (or C == channels when channels > 0) and H, W ≥ 1.
py::array_t<float> image_array(py::handle obj, const char* what, int channels = 0);
// A view of such an array (rows may have any stride).
ibl::ImageView view_of(const py::array_t<float>& a);
// An owned copy of an image argument (library calls that keep the pixels take an Image).
ibl::Image to_image(py::handle obj, const char* what, int channels = 0);
// to_image, then the library's pixel check (io::check_pixels: NaN/Inf/negative raise ValueError).
ibl::Image to_checked_image(py::handle obj, const char* what);

// An environment map over an image argument for one library call (constructed with the GIL held, used
// without it, destroyed with it). When the argument is an array this module returned (a whole image:
// float32, its own shape and strides) that no other call holds, its ibl::Image is lent to the map —
// moved in, and moved back by the destructor; moves keep the pixels where they are, so the array stays
// valid throughout — else the pixels are copied. The library call validates the pixels itself (lights/
// does); `check` copies and runs io::check_pixels first for calls that do not.
class EnvArg {
 public:
  EnvArg(py::handle img, const std::string& mapping, double dead_angle, const char* what, bool check);
  ~EnvArg();
  EnvArg(const EnvArg&) = delete;
  EnvArg& operator=(const EnvArg&) = delete;
  const ibl::sphere::EnvMap& env() const { return *env_; }
  bool lent() const { return owned_ != nullptr; }

 private:
  py::object keep_;
  struct OwnedImage* owned_ = nullptr;
  std::optional<ibl::sphere::EnvMap> env_;
};

// The mapping named `name` ("latlong", "mirrorball", …; "auto" detects from the shape) of a w × h image.
ibl::sphere::Mapping mapping_of(const std::string& name, int w, int h, double dead_angle_deg = 0.0);

// ---- small vectors ------------------------------------------------------------------------------

ibl::Vec3 to_vec3(py::handle obj, const char* what);
std::vector<ibl::Vec3> to_vec3s(py::handle obj, const char* what);  // (N, 3) or (3,)
ibl::Mat3 to_mat3(py::handle obj, const char* what);                // (3, 3)
py::array_t<double> vec3_array(const std::vector<ibl::Vec3>& v);    // (N, 3)
py::tuple vec3_tuple(ibl::Vec3 v);
py::array_t<double> mat3_array(const ibl::Mat3& m);

// ---- progress -----------------------------------------------------------------------------------

// A library ProgressFn that calls the Python callable `cb(stage: str, fraction: float)` with the GIL
// held, at most once per 1/200 of progress and stage change (so that a tqdm bar stays cheap), from
// whichever thread reports. An exception the callback raises stops further calls and is raised again
// by rethrow() when the library call has returned.
class Progress {
 public:
  explicit Progress(py::object cb);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  const ibl::ProgressFn& fn() const { return fn_; }
  void rethrow();  // with the GIL held

 private:
  struct State;
  std::shared_ptr<State> state_;
  ibl::ProgressFn fn_;
};

// ---- registration (one function per binding file, called by module.cpp) --------------------------

void init_errors(py::module_& m);
void init_core(py::module_& m);
void init_io(py::module_& m);
void init_sh(py::module_& m);
void init_capture(py::module_& m);
void init_lights(py::module_& m);
void init_ilf(py::module_& m);
void init_capture_ball(py::module_& m);
#ifdef IBLKIT_HAVE_GEOMETRY
void init_geometry(py::module_& m);
void init_lab(py::module_& m);
void init_fusion(py::module_& m);
void init_nearfield(py::module_& m);
void init_render(py::module_& m);
void init_augment(py::module_& m);
#endif

}  // namespace iblpy
