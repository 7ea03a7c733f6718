// Files engines load: the specular cube map with its mip chain (KTX2, or EXR faces / lat-longs per
// level), the irradiance cube map, the DFG table; and the world frames of the engines.
//
// Frames: iblkit's world (+Y up, right-handed; a lat-long's centre looks towards +X, as three.js's
// equirectangular maps do) is the frame of three.js, glTF and the web viewer. Filament's cmgen puts
// the same lat-long into a frame turned by 90° about +Y, and a cube map into its mirror image
// (sh::filament_frame); `filament` writes the maps in that frame, so that they equal what cmgen
// writes for the same file.
#pragma once
#include <string>

#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"
#include "iblkit/engine/cube_chain.h"
#include "iblkit/engine/ktx2.h"
#include "iblkit/sphere/mapping.h"

namespace ibl::engine {

enum class EngineFrame { Iblkit, Filament };
std::string engine_frame_name(EngineFrame f);
EngineFrame parse_engine_frame(const std::string& name);  // "iblkit" (alias "threejs", "gltf"), "filament"
// The orthogonal matrix that takes iblkit's world to the frame (the `rotation` of SpecularDesc) for
// a probe of mapping k: Filament's depends on it (sh::filament_frame: a rotation for lat-longs, a
// mirror for cube maps).
Mat3 frame_rotation(EngineFrame f, sphere::MappingKind k = sphere::MappingKind::LatLong);

// A cube chain as a KTX2 cube map, RGBA16F (alpha 1), every level.
Ktx2Texture cube_ktx2(const CubeChain& cube);
// One face of level m, as an RGB image.
Image cube_face(const CubeChain& cube, int level, int face);
// dir/m<level>_<face>.exr, face px nx py ny pz nz (cmgen's --ibl-ld names); creates dir.
void write_cube_faces(const std::string& dir, const CubeChain& cube);
// dir/m<level>.exr: level m as a lat-long of 4·S_m × 2·S_m (bilinear from the level's faces).
void write_cube_latlongs(const std::string& dir, const CubeChain& cube);
// A one-level cube (a 6S × S strip) to .ktx2, or to a folder of six faces px.exr … nz.exr
// (anything else than .ktx2 is taken as the folder).
void write_cube(const std::string& path, const Image& strip);
// The DFG table (dfg.h) to .png (8-bit data, no sRGB curve), .exr (float) or .ktx2 (R16G16_SFLOAT).
void write_dfg(const std::string& path, const Image& table);

}  // namespace ibl::engine
