// ibl::Error as Python exceptions (docs/python.md, "Errors"): iblkit.Error is the base; each
// ibl::ErrorKind gets a subclass that is also the built-in exception a Python user would catch:
//   Io → IoError(Error, OSError), Format → FormatError(Error, ValueError),
//   Value → InvalidValue(Error, ValueError), Unsupported → Unsupported(Error, NotImplementedError),
//   Internal → InternalError(Error, RuntimeError).
// The message is the library's, unchanged; the exception's `kind` attribute names the ErrorKind.
#include "common.h"

#include "iblkit/core/error.h"

namespace iblpy {

namespace {

PyObject* g_error = nullptr;
PyObject* g_kind[5] = {};

PyObject* make_class(py::module_& m, const char* name, PyObject* bases, const char* doc) {
  std::string full = std::string("iblkit.") + name;
  PyObject* cls = PyErr_NewExceptionWithDoc(full.c_str(), doc, bases, nullptr);
  if (!cls) throw py::error_already_set();
  m.add_object(name, py::handle(cls));  // the module keeps a reference (classes live as long as it)
  return cls;
}

const char* kind_name(ibl::ErrorKind k) {
  switch (k) {
    case ibl::ErrorKind::Io:
      return "io";
    case ibl::ErrorKind::Format:
      return "format";
    case ibl::ErrorKind::Value:
      return "value";
    case ibl::ErrorKind::Unsupported:
      return "unsupported";
    case ibl::ErrorKind::Internal:
      return "internal";
  }
  return "internal";
}

}  // namespace

void init_errors(py::module_& m) {
  g_error = make_class(m, "Error", PyExc_Exception,
                       "Base of every error the iblkit library raises; `kind` names the library's ErrorKind "
                       "(io, format, value, unsupported, internal).");
  auto sub = [&](const char* name, PyObject* builtin, const char* doc) {
    py::tuple bases = py::make_tuple(py::handle(g_error), py::handle(builtin));
    return make_class(m, name, bases.ptr(), doc);
  };
  g_kind[int(ibl::ErrorKind::Io)] =
      sub("IoError", PyExc_OSError, "A file is missing, unreadable or unwritable (an OSError).");
  g_kind[int(ibl::ErrorKind::Format)] =
      sub("FormatError", PyExc_ValueError,
          "A file parses but is not what it claims: corrupt, truncated, unknown format (a ValueError).");
  g_kind[int(ibl::ErrorKind::Value)] =
      sub("InvalidValue", PyExc_ValueError,
          "A value is out of range: NaN/Inf/negative pixels, a zero count, a wrong size (a ValueError).");
  g_kind[int(ibl::ErrorKind::Unsupported)] =
      sub("Unsupported", PyExc_NotImplementedError,
          "A valid request this build cannot serve (an optional part not built).");
  g_kind[int(ibl::ErrorKind::Internal)] =
      sub("InternalError", PyExc_RuntimeError, "A bug in iblkit: an invariant failed.");

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ibl::Error& e) {
      PyObject* cls = g_kind[int(e.kind())];
      py::object exc = py::reinterpret_steal<py::object>(PyObject_CallFunction(cls, "s", e.what()));
      if (!exc) return;  // the call set its own error
      PyObject_SetAttrString(exc.ptr(), "kind", py::str(kind_name(e.kind())).ptr());
      PyErr_SetObject(cls, exc.ptr());
    }
  });
}

}  // namespace iblpy
