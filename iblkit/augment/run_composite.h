// The one composite entry point: what `iblkit composite`, `iblkit view --composite` and Python's
// iblkit.composite() all call, so that the pipeline — the object made, the captured light read and placed,
// the baseline's median cut, the backend chosen and run — is assembled in one place.
#pragma once
#include <string>
#include <vector>

#include "iblkit/augment/composite.h"
#include "iblkit/augment/load.h"
#include "iblkit/core/image.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/render/objects.h"
#include "iblkit/render/shading.h"

namespace ibl::augment {

enum class Backend {
  Cpu,   // the ray-traced reference (composite.h)
  Gl,    // OpenGL: shadow maps and the soft sphere term (augment/gl/compositor.h)
  Auto,  // GL when a context can be made, else the CPU
};
// "cpu", "gl", "auto"; parse_backend throws ibl::Error naming the three on anything else.
const char* backend_name(Backend b);
Backend parse_backend(const std::string& name);

// The object a composite inserts when none is named: a 0.3 m blob of 20k triangles resting above a table
// or floor at y = 0 (a hand-sized object; `iblkit render`'s 0.8 m, 100k-triangle blob is a showpiece).
inline render::ObjectDesc inserted_object_defaults() { return {"blob", 0.3, 20000, {0, 0.15, 0}}; }

struct CompositeJob {
  render::ObjectDesc object = inserted_object_defaults();  // made by render::make_object
  render::Material material{{0.7, 0.7, 0.7}, {0, 0, 0}};   // its surface (render::check_material)
  LightInput light;                                        // the captured light and the proxy, from files (load.h)
  int median_cut = 0;                                      // > 0: the baseline of this many median-cut lights
  Backend backend = Backend::Cpu;
  CompositeDesc desc;  // sampling, seed, shadows, the GL options, progress
};

// A composite's inputs once read: the object's mesh and the light with its proxy (and the light's warnings).
struct CompositeScene {
  geometry::TriMesh object;
  LoadedLight light;
};
// Makes the object and reads the light (checked against where the object goes), then the median cut.
CompositeScene prepare_composite(const CompositeJob& job);

struct CompositeRun {
  CompositeResult result;          // its warnings begin with the light's
  Backend backend = Backend::Cpu;  // the one that ran (Auto resolved)
  std::string light_source;        // LocalRadiance::source
  std::vector<std::string> notes;  // what the caller may tell the user (the backend auto chose)
};
// `photo` (linear RGB) seen by `cam` (its size the photograph's). Throws ibl::Error on bad input, and
// (ErrorKind::Unsupported) for Backend::Gl when iblkit has no OpenGL or no context can be made.
CompositeRun run_composite(const Image& photo, const geometry::Camera& cam, const CompositeJob& job);
// The same with the scene already in memory (Python's LocalRadiance and TriMesh); job.object, job.light and
// job.median_cut are not read.
CompositeRun run_composite(const Image& photo, const geometry::Camera& cam, const CompositeJob& job,
                           const CompositeScene& scene);

// The GL backend's face, defined in augment/gl/composite_gl.cpp when iblkit is built with OpenGL: whether
// a context can be made (why not, when not), and its composite (gl::composite).
bool gl_backend_available(std::string* why);
CompositeResult gl_backend_composite(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                                     const LocalRadiance& light, const geometry::TriMesh& object,
                                     const render::Material& material, const CompositeDesc& desc);

}  // namespace ibl::augment
