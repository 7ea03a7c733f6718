// numpy ↔ library conversions and the progress callback (common.h).
#include "common.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <mutex>

#include <fmt/format.h>

#include "iblkit/core/error.h"
#include "iblkit/io/image_io.h"

namespace iblpy {

namespace {

// TypeError unless obj is an array (or a sequence numpy turns into one) of a real numeric dtype.
py::array as_numeric_array(py::handle obj, const char* what) {
  py::array a;
  if (py::isinstance<py::array>(obj)) {
    a = py::reinterpret_borrow<py::array>(obj);
  } else {
    if (obj.is_none() || py::isinstance<py::str>(obj) || py::isinstance<py::bytes>(obj))
      throw py::type_error(
          fmt::format("{}: expected a numpy array, got {}", what, std::string(py::str(obj.get_type()))));
    try {
      a = py::array::ensure(obj);
    } catch (py::error_already_set&) {
      a = py::array();
    }
    if (!a)
      throw py::type_error(
          fmt::format("{}: expected a numpy array, got {}", what, std::string(py::str(obj.get_type()))));
  }
  char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::type_error(
        fmt::format("{}: expected a real numeric array, got dtype {}", what, std::string(py::str(a.dtype()))));
  return a;
}

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

}  // namespace

// ---- images -------------------------------------------------------------------------------------

// The base of every image array the module returns: the library's Image, and whether a call holds it.
struct OwnedImage {
  ibl::Image img;
  float* data = nullptr;  // where the pixels are (img is empty while lent)
  int width = 0, height = 0, channels = 0;
  std::atomic<bool> lent{false};
};

namespace {
constexpr const char* kOwnedName = "iblkit.Image";
}  // namespace

py::array to_array(ibl::Image img, bool squeeze) {
  auto* owned = new OwnedImage;
  owned->img = std::move(img);
  owned->data = owned->img.data();
  owned->width = owned->img.width();
  owned->height = owned->img.height();
  owned->channels = owned->img.channels();
  py::capsule base(owned, kOwnedName,
                   [](PyObject* cap) { delete static_cast<OwnedImage*>(PyCapsule_GetPointer(cap, kOwnedName)); });
  const py::ssize_t h = owned->height, w = owned->width, c = owned->channels;
  const py::ssize_t f = sizeof(float);
  if (squeeze && c == 1) return py::array_t<float>({h, w}, {w * f, f}, owned->data, base);
  return py::array_t<float>({h, w, c}, {w * c * f, c * f, f}, owned->data, base);
}

EnvArg::EnvArg(py::handle img, const std::string& mapping, double dead_angle, const char* what, bool check) {
  if (!check && py::isinstance<py::array>(img)) {
    py::array a = py::reinterpret_borrow<py::array>(img);
    py::object b = a.base();
    PyObject* base = b.ptr();
    if (base && PyCapsule_CheckExact(base) && PyCapsule_IsValid(base, kOwnedName)) {
      auto* o = static_cast<OwnedImage*>(PyCapsule_GetPointer(base, kOwnedName));
      const py::ssize_t f = sizeof(float);
      bool whole = a.dtype().is(py::dtype::of<float>()) && a.data() == o->data && a.ndim() == 3 &&
                   a.shape(0) == o->height && a.shape(1) == o->width && a.shape(2) == o->channels &&
                   a.strides(2) == f && a.strides(1) == o->channels * f && a.strides(0) == o->width * o->channels * f;
      bool expected = false;
      std::optional<ibl::sphere::Mapping> m;
      if (whole) m = mapping_of(mapping, o->width, o->height, dead_angle);  // before the lend: it may throw
      if (whole && o->lent.compare_exchange_strong(expected, true)) {
        keep_ = py::reinterpret_borrow<py::object>(img);
        owned_ = o;
        env_.emplace(std::move(o->img), *m);  // sizes agree: the constructor does not throw
        return;
      }
    }
  }
  ibl::Image im = check ? to_checked_image(img, what) : to_image(img, what);
  ibl::sphere::Mapping m = mapping_of(mapping, im.width(), im.height(), dead_angle);
  env_.emplace(std::move(im), m);
}

EnvArg::~EnvArg() {
  if (owned_) {
    owned_->img = std::move(env_->image);  // the same buffer: the array never saw it move
    owned_->lent.store(false);
  }
}

py::array_t<float> image_array(py::handle obj, const char* what, int channels) {
  py::array a = as_numeric_array(obj, what);
  if (a.dtype().kind() != 'f')
    throw py::type_error(fmt::format("{}: expected a float array (float32 or float64), got dtype {}", what,
                                     std::string(py::str(a.dtype()))));
  if (a.ndim() != 2 && a.ndim() != 3)
    throw py::value_error(
        fmt::format("{}: expected an image of shape (H, W) or (H, W, C), got {}", what, shape_text(a)));
  py::ssize_t c = a.ndim() == 3 ? a.shape(2) : 1;
  if (a.shape(0) < 1 || a.shape(1) < 1 || c < 1 || c > 4 || (channels > 0 && c != channels))
    throw py::value_error(fmt::format("{}: expected an image of shape (H, W, {}) with H, W ≥ 1, got {}", what,
                                      channels > 0 ? std::to_string(channels) : std::string("C ≤ 4"), shape_text(a)));
  if (a.shape(0) > 65536 || a.shape(1) > 65536)
    throw py::value_error(fmt::format("{}: {} exceeds the largest image side, 65536", what, shape_text(a)));
  // Pixels must be contiguous within a row (channel stride 4 bytes, pixel stride C·4); rows may be
  // strided. Anything else (float64, a transposed or column-sliced array) is copied once.
  bool ok = a.dtype().is(py::dtype::of<float>()) && reinterpret_cast<uintptr_t>(a.data()) % 4 == 0;
  if (ok) {
    if (a.ndim() == 3)
      ok = a.strides(2) == 4 && a.strides(1) == 4 * c;
    else
      ok = a.strides(1) == 4;
    ok = ok && a.strides(0) > 0 && a.strides(0) % 4 == 0 && a.strides(0) >= a.shape(1) * c * 4;
  }
  if (ok) return py::reinterpret_borrow<py::array_t<float>>(a);
  return py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
}

ibl::ImageView view_of(const py::array_t<float>& a) {
  int c = a.ndim() == 3 ? static_cast<int>(a.shape(2)) : 1;
  return ibl::ImageView(a.data(), static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)), c, a.strides(0) / 4);
}

ibl::Image to_image(py::handle obj, const char* what, int channels) {
  py::array_t<float> a = image_array(obj, what, channels);
  ibl::ImageView v = view_of(a);
  ibl::Image img(v.width(), v.height(), v.channels());
  const size_t row = static_cast<size_t>(v.width()) * v.channels();
  for (int y = 0; y < v.height(); ++y) std::memcpy(img.pixel(0, y), v.pixel(0, y), row * sizeof(float));
  return img;
}

ibl::Image to_checked_image(py::handle obj, const char* what) {
  ibl::Image img = to_image(obj, what);
  ibl::io::check_pixels(img, what, false);
  return img;
}

ibl::sphere::Mapping mapping_of(const std::string& name, int w, int h, double dead_angle_deg) {
  using ibl::sphere::MappingKind;
  MappingKind k = name == "auto" ? ibl::sphere::detect_mapping(w, h) : ibl::sphere::parse_mapping(name, "mapping");
  double aspect = ibl::sphere::Mapping::aspect(k);
  if (std::abs(static_cast<double>(w) / h - aspect) > 1e-9 * aspect)
    ibl::fail(ibl::ErrorKind::Value, "mapping {}: an image of {}x{} does not have its aspect ratio {:g} (width/height)",
              ibl::sphere::mapping_name(k), w, h, aspect);
  return ibl::sphere::Mapping(k, w, h, dead_angle_deg);
}

// ---- small vectors ------------------------------------------------------------------------------

std::vector<ibl::Vec3> to_vec3s(py::handle obj, const char* what) {
  py::array a = as_numeric_array(obj, what);
  if (!((a.ndim() == 2 && a.shape(1) == 3) || (a.ndim() == 1 && a.shape(0) == 3)))
    throw py::value_error(fmt::format("{}: expected shape (N, 3) or (3,), got {}", what, shape_text(a)));
  auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  size_t n = a.ndim() == 2 ? static_cast<size_t>(a.shape(0)) : 1;
  std::vector<ibl::Vec3> out(n);
  const double* p = d.data();
  for (size_t i = 0; i < n; ++i) out[i] = {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
  return out;
}

ibl::Vec3 to_vec3(py::handle obj, const char* what) {
  py::array a = as_numeric_array(obj, what);
  if (a.size() != 3) throw py::value_error(fmt::format("{}: expected 3 numbers, got shape {}", what, shape_text(a)));
  auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  return {d.data()[0], d.data()[1], d.data()[2]};
}

ibl::Mat3 to_mat3(py::handle obj, const char* what) {
  py::array a = as_numeric_array(obj, what);
  if (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3)
    throw py::value_error(fmt::format("{}: expected a 3×3 matrix, got shape {}", what, shape_text(a)));
  auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  ibl::Mat3 m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m.m[i][j] = d.data()[3 * i + j];
  return m;
}

py::array_t<double> vec3_array(const std::vector<ibl::Vec3>& v) {
  py::array_t<double> a({static_cast<py::ssize_t>(v.size()), py::ssize_t(3)});
  double* p = a.mutable_data();
  for (size_t i = 0; i < v.size(); ++i) {
    p[3 * i] = v[i].x;
    p[3 * i + 1] = v[i].y;
    p[3 * i + 2] = v[i].z;
  }
  return a;
}

py::tuple vec3_tuple(ibl::Vec3 v) { return py::make_tuple(v.x, v.y, v.z); }

py::array_t<double> mat3_array(const ibl::Mat3& m) {
  py::array_t<double> a({py::ssize_t(3), py::ssize_t(3)});
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a.mutable_at(i, j) = m.m[i][j];
  return a;
}

// ---- progress -----------------------------------------------------------------------------------

struct Progress::State {
  py::object cb;
  std::mutex mu;
  std::string stage;
  double last = -1;
  bool failed = false;
  std::optional<py::error_already_set> error;
};

Progress::Progress(py::object cb) {
  if (cb.is_none()) return;
  if (!PyCallable_Check(cb.ptr())) throw py::type_error("progress: expected a callable progress(stage, fraction)");
  state_ = std::make_shared<State>();
  state_->cb = std::move(cb);
  std::weak_ptr<State> weak = state_;
  fn_ = [weak](std::string_view stage, double fraction) {
    auto s = weak.lock();
    if (!s) return;
    std::lock_guard<std::mutex> lock(s->mu);
    if (s->failed) return;
    bool new_stage = stage != s->stage;
    if (!new_stage && fraction < 1.0 && fraction - s->last < 0.005) return;
    if (!new_stage && fraction <= s->last) return;
    s->stage = std::string(stage);
    s->last = fraction;
    py::gil_scoped_acquire gil;
    try {
      s->cb(s->stage, std::clamp(fraction, 0.0, 1.0));
    } catch (py::error_already_set& e) {
      s->failed = true;
      s->error.emplace(std::move(e));
    }
  };
}

Progress::~Progress() {
  if (state_) {
    py::gil_scoped_acquire gil;  // the callable and a stored error are Python objects
    state_->error.reset();
    state_->cb = py::object();
  }
}

void Progress::rethrow() {
  if (state_ && state_->error) {
    py::error_already_set e = std::move(*state_->error);
    state_->error.reset();
    throw e;
  }
}

}  // namespace iblpy
