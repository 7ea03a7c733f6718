// Reading iblkit.scene/1 JSON scene files (docs/formats.md, "Scenes").
#pragma once
#include <string>

#include "iblkit/lab/scene.h"

namespace ibl::lab {

// Loads and builds a scene (build = false leaves Scene::build to the caller, who may add objects
// first: lab/view.h). `path` is a file, or the name of a built-in scene in examples/
// ("low-scene1", "low-scene2", "t-corridor", "crypt"). Paths inside the file (meshes, textures,
// environment probes, the proxy) are relative to the file. Throws ibl::Error naming the file and
// the field at fault.
Scene load_scene(const std::string& path, bool build = true);

// The file a scene name or path resolves to (examples/NAME.json for built-in names).
std::string resolve_scene_path(const std::string& name_or_path);

}  // namespace ibl::lab
