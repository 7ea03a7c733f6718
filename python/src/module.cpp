// The Python module iblkit._iblkit (docs/python.md); iblkit/__init__.py re-exports it. One
// registration function per library module (common.h), each in its own bind_<module>.cpp.
#include "common.h"

PYBIND11_MODULE(_iblkit, m) {
  m.doc() = "iblkit: image-based lighting from numpy (the C++ library's Python bindings; docs/python.md).";
  iblpy::init_errors(m);
  iblpy::init_core(m);
  iblpy::init_io(m);
  iblpy::init_sh(m);
  iblpy::init_lights(m);
  iblpy::init_ilf(m);
  iblpy::init_capture_ball(m);
  iblpy::init_capture(m);
#ifdef IBLKIT_HAVE_GEOMETRY
  iblpy::init_geometry(m);
  iblpy::init_lab(m);
  iblpy::init_fusion(m);
  iblpy::init_nearfield(m);
  iblpy::init_render(m);
  iblpy::init_augment(m);
  m.attr("have_geometry") = true;
#else
  m.attr("have_geometry") = false;
#endif
}
