// core/: the size of the thread pool every parallel loop of the library runs on (oneTBB).
#include "common.h"

#include <memory>
#include <mutex>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include "iblkit/core/error.h"

namespace iblpy {

namespace {
std::mutex g_mu;
std::unique_ptr<tbb::global_control> g_control;
}  // namespace

void init_core(py::module_& m) {
  m.def(
      "set_threads",
      [](int n) {
        std::lock_guard<std::mutex> lock(g_mu);
        g_control.reset();
        if (n < 0 || n > 4096) ibl::fail(ibl::ErrorKind::Value, "set_threads: n must be in 0..4096 (got {})", n);
        if (n > 0) g_control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, n);
      },
      py::arg("n"),
      R"doc(Limits the threads one library call uses to n (0: all cores, the default). Calls from several
Python threads run at once (each releases the GIL), each on up to n threads.)doc");
  m.def(
      "threads",
      [] { return static_cast<int>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)); },
      "The threads one library call may use now.");
}

}  // namespace iblpy
