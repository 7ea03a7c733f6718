// The one composite entry point: what `iblkit composite`, `iblkit view --composite` and Python's
// iblkit.composite() all call, so that the pipeline — the object made, the captured light read and placed,
// the baseline's median cut, the backend chosen and run — is assembled in one place.
#pragma once
#include <string>
#include <vector>

#include "iblkit/augment/composite.h"
#include "iblkit/augment/load.h"
#include "iblkit/augment/match.h"
#include "iblkit/augment/register.h"
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

// The object a composite inserts when none is named: a 0.3 m blob of 20k triangles resting on a table or floor
// at y = 0 (its lowest point 0.1 mm above it; the blob's size scales its shape, which reaches 1.1 cm lower
// than its centre minus half its size); a hand-sized object; `iblkit render`'s 0.8 m, 100k-triangle blob is a
// showpiece.
inline render::ObjectDesc inserted_object_defaults() { return {"blob", 0.3, 20000, {0, 0.161, 0}}; }

// The radiometric match of the light to the photograph (match.h): Auto estimates the gains whenever the
// light is a probe's map (one probe, fused probes, a probe image: maps that see the proxy; not an SH grid's,
// which is band-limited) and multiplies the light by them; GreyCard does the same from the pixels of
// grey_card alone (a matte card both see: any light, an SH grid's too); Off leaves the light as captured.
enum class Match { Auto, Off, GreyCard };

// Registration of the light (augment/register.h): off; check (its turn and position measured and reported, not
// applied); yaw (the turn applied); pose (turn, position, turn again, applied).
enum class Register { Off, Check, Yaw, Pose };
Register parse_register(const std::string& name);

struct CompositeJob {
  render::ObjectDesc object = inserted_object_defaults();  // made by render::make_object
  render::Material material{{0.7, 0.7, 0.7}, {0, 0, 0}};   // its surface (render::check_material)
  LightInput light;                                        // the captured light and the proxy, from files (load.h)
  int median_cut = 0;            // > 0: the baseline of this many median-cut lights (cut after the match)
  Match match = Match::Auto;     // the light put in the photograph's units (match.h)
  Register reg = Register::Off;  // the light's turn about +Y from the proxy both see (register.h), before the match
  double saturated = 0;          // linear value at which the photograph saturates (0: never), left out of the match
  PixelRect grey_card;           // Match::GreyCard: the card's pixels in the photograph
  Backend backend = Backend::Cpu;
  CompositeDesc desc;  // sampling, seed, shadows, the GL options, progress
};

// A composite's inputs once read: the object's mesh and the light with its proxy (and the light's warnings).
struct CompositeScene {
  geometry::TriMesh object;
  LoadedLight light;
  MatchResult match;               // the gains estimated (match.valid false: none)
  bool matched = false;            // the light was multiplied by match.gain
  YawFit yaw;                      // job.reg: the turn registered (yaw.valid false: not measured or no points)
  bool turned = false;             // the light was turned by yaw.yaw_deg
  PositionFit position;            // job.reg check or pose: its position registered (offset: all moves summed)
  bool moved = false;              // the light's centre was moved by position.offset
  std::vector<std::string> notes;  // the match, in words
};
// Makes the object and reads the light (checked against where the object goes); with the photograph and
// its camera, the radiometric match (job.match); then the median cut.
CompositeScene prepare_composite(const CompositeJob& job, const Image* photo = nullptr,
                                 const geometry::Camera* cam = nullptr);
// The registration (job.reg) and the match alone, on a scene made otherwise (Python's in-memory light): estimates and
// applies them.
void match_light(CompositeScene& scene, const Image& photo, const geometry::Camera& cam, const CompositeJob& job);

struct CompositeRun {
  CompositeResult result;          // its warnings begin with the light's
  Backend backend = Backend::Cpu;  // the one that ran (Auto resolved)
  std::string light_source;        // LocalRadiance::source
  geometry::TriMesh proxy;         // the local scene it composited on (for the overlay layer)
  std::vector<std::string> notes;  // what the caller may tell the user (the backend auto chose, the match)
  MatchResult match;               // the gains estimated (match.valid false: none)
  bool matched = false;            // the light was multiplied by match.gain
  YawFit yaw;                      // the turn registered (job.reg)
  bool turned = false;             // and applied
  PositionFit position;            // the position registered
  bool moved = false;              // and applied
};
// `photo` (linear RGB) seen by `cam` (its size the photograph's). Throws ibl::Error on bad input, and
// (ErrorKind::Unsupported) for Backend::Gl when iblkit has no OpenGL or no context can be made.
CompositeRun run_composite(const Image& photo, const geometry::Camera& cam, const CompositeJob& job);
// The same with the scene already in memory (Python's LocalRadiance and TriMesh); job.object, job.light and
// job.median_cut and job.match are not read (prepare_composite's and match_light's).
CompositeRun run_composite(const Image& photo, const geometry::Camera& cam, const CompositeJob& job,
                           const CompositeScene& scene);

// The GL backend's face, defined in augment/gl/composite_gl.cpp when iblkit is built with OpenGL: whether
// a context can be made (why not, when not), and its composite (gl::composite).
bool gl_backend_available(std::string* why);
CompositeResult gl_backend_composite(const Image& photo, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                                     const LocalRadiance& light, const geometry::TriMesh& object,
                                     const render::Material& material, const CompositeDesc& desc);

}  // namespace ibl::augment
