// A view of a scene lit by a luminaire, as `iblkit nearfield render` makes it: the textured spotlights
// of a near-field dataset (or the one far-field spotlight of an IES file) rendered with shadow rays,
// and for a lab dataset the same view lit exactly by the virtual luminaire and by its far-field
// approximation, with the errors of both against the exact picture (render.h's CPU reference).
#pragma once
#include <optional>
#include <string>

#include "iblkit/core/progress.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/nearfield/dataset.h"
#include "iblkit/nearfield/luminaire.h"
#include "iblkit/nearfield/render.h"

namespace ibl::nearfield {

struct SceneRenderDesc {
  std::string dataset;      // iblkit.nearfield/1 manifest whose textured spotlights light the scene, or
  std::string ies;          // an IES LM-63 file rendered as one far-field spotlight (exactly one of the two)
  double ies_scale = 1;     // multiplies the IES file's candela values
  std::string exact;        // also the lab luminaire of this name lit exactly ("auto": the dataset's own;
                            // "" or "none": no comparison; ignored with `ies`)
  bool far_field = true;    // with `exact`: also the far-field approximation (one goniometric point)
  Placement placement;      // the luminaire: centre of S and where it points
  geometry::Camera camera;  // the view
  bool shadows = true;      // shadow rays (false: no visibility tests)
  bool srgbe = false;       // also sum through the paper's 8-bit sRGBE frame buffer (passes of 3) and
                            // report its error against the float sum
};

struct SceneRender {
  std::string label;               // the dataset's name, or the IES file's path
  size_t spotlights = 0;           // textured spotlights in `near_field`
  Image near_field;                // outgoing radiance (RGB, W/(sr·m²)) under the spotlights (Eq. 14)
  std::optional<Image> exact;      // the same view lit by the virtual luminaire (with `exact`)
  std::optional<Image> far_field;  // lit by the far-field spotlight (with `exact` and `far_field`)
  std::optional<ErrorStats> near_field_error, far_field_error;  // against `exact`
  std::optional<ErrorStats> srgbe_error;  // the sRGBE frame buffer against `near_field` (with `srgbe`)
  size_t srgbe_passes = 0;                // passes of 3 spotlights through that frame buffer
  double setup_seconds = 0;               // reading the dataset and building its E' textures (or the IES file)
  double render_seconds = 0;              // rendering `near_field`
  double exact_seconds = 0;               // rendering `exact`
};

// The lab luminaire a dataset is compared with: `name` ("auto": the one the dataset was simulated from),
// none for "" or "none". Throws ibl::Error when "auto" meets a measured dataset or the name is unknown.
std::optional<Luminaire> exact_luminaire(const Dataset& ds, const std::string& name);

// Renders the scene as `desc` says; throws ibl::Error for bad parameters or files.
SceneRender render_scene(const SceneView& scene, const SceneRenderDesc& desc, const ProgressFn& progress = {});

}  // namespace ibl::nearfield
