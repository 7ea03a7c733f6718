// A whole EXT_lights_image_based light on disk: the glTF document (sh::gltf_ibl_text: irradiance
// coefficients, specularImageSize, specularImages) and, beside it, the prefiltered specular cube as
// the extension's images — one PNG per level × face, RGBD-packed (io/rgbd.h: 4 channels, which the
// extension reads as HDR) and flipped upside down (PNG row r holds row S−1−r of the GL-oriented face:
// the extension's "flipped about its vertical axis", done as its reference loader, Babylon.js, undoes
// it — it uploads every face with invertY). docs/conventions.md ("EXT_lights_image_based specular
// images") gives the sources and the tests.
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/engine/cube_chain.h"
#include "iblkit/sh/coeffs.h"

namespace ibl::engine {

// A GL-oriented face (RGB radiance, texel (s, t) with s right, t down) → the 4-channel image its PNG
// holds (byte/255 values: RGBD, rows reversed); and back (decoded radiance, rows restored).
Image gltf_specular_image(const Image& face);
Image gltf_specular_face(const Image& image);

// The cube chain whose faces a pattern with "{level}" and "{face}" (px nx py ny pz nz) names, e.g.
// what `iblkit specular --faces DIR` writes: "DIR/m{level}_{face}.exr"; any image iblkit reads, as
// linear radiance in the GL cube orientation. Levels 0, 1, … as long as all six faces exist (a level
// with some but not all six is an error); the faces of a level square and equal, level 0 a power of
// two, level m of size max(1, S >> m).
CubeChain read_cube_faces(const std::string& pattern);

// The image file names beside `gltf_path` ("<stem>_m<level>_<face>.png", the URIs in the document).
std::string gltf_specular_image_name(const std::string& gltf_path, int level, int face);

// Writes the glTF document to `gltf_path` and its specular images beside it (each atomically; a
// command's OutputTransaction removes them all when it fails). Returns the paths written, images
// first, the document last.
std::vector<std::string> write_gltf_ibl(const std::string& gltf_path, const sh::Coeffs& radiance,
                                        const CubeChain& specular);

}  // namespace ibl::engine
