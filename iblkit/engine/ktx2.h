// KTX 2.0 textures of 16-bit floats, written from the specification [1] (no KTX library is packaged
// in Debian): 2D textures and cube maps, every mip level, uncompressed (supercompressionScheme 0).
//
// What a file holds (byte offsets from [1] §3):
//   identifier «KTX 20»\r\n\x1A\n; header: vkFormat, typeSize 2, pixelWidth, pixelHeight,
//   pixelDepth 0, layerCount 0, faceCount 1 or 6, levelCount, supercompression 0; the index
//   (DFD, KVD offsets and lengths; SGD 0, 0); the level index (offset, length, uncompressed length
//   of each level, level 0 first); the Data Format Descriptor (one basic block [2] §5: RGBSDA,
//   BT.709 primaries, linear transfer, one sample per channel, SIGNED|FLOAT, bounds −1.0f/1.0f);
//   key/value data (KTXwriter = "iblkit", and KTXorientation = "rd" for 2D textures); then the
//   levels, the smallest first, each starting at a multiple of 8 bytes (lcm of the texel size 8 or
//   4 and 4). Within a level: faces +X −X +Y −Y +Z −Z, each row-major with row 0 at the top (the
//   first row in memory is the one a GL/Vulkan sampler reads at t = 0).
// Formats: VK_FORMAT_R16G16B16A16_SFLOAT (97; RGB images get alpha 1) and VK_FORMAT_R16G16_SFLOAT
// (83; two-channel tables such as the split-sum DFG table).
//
// References
//  [1] Khronos, "KTX File Format Specification, version 2.0" (registry.khronos.org/KTX/specs/2.0).
//  [2] Khronos, "Data Format Specification" 1.3, §5 (basic descriptor block) and §17 (example
//      descriptors for Vulkan formats).
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/image.h"

namespace ibl::engine {

inline constexpr int kVkFormatRgba16f = 97;  // VK_FORMAT_R16G16B16A16_SFLOAT
inline constexpr int kVkFormatRg16f = 83;    // VK_FORMAT_R16G16_SFLOAT

struct Ktx2Texture {
  int vk_format = kVkFormatRgba16f;        // one of the two above
  int faces = 1;                           // 1 (2D) or 6 (cube map)
  std::vector<std::vector<Image>> levels;  // levels[m][face]: (width >> m) × (height >> m), any channels
                                           // (missing channels: 0, alpha 1; extra ones dropped)
  int width() const { return levels.empty() || levels[0].empty() ? 0 : levels[0][0].width(); }
  int height() const { return levels.empty() || levels[0].empty() ? 0 : levels[0][0].height(); }
};

// The file's bytes; throws ibl::Error when the levels are not a valid chain (each level half the
// one above, rounded down, at least 1; square faces for a cube map; the same count of faces).
std::string ktx2_bytes(const Ktx2Texture& tex);
// Writes ktx2_bytes atomically.
void write_ktx2(const std::string& path, const Ktx2Texture& tex);
// Reads a KTX2 file of one of the two formats above, uncompressed (what write_ktx2 writes; other
// writers' files of these formats too). Images come back with 4 or 2 channels. Throws ibl::Error
// naming the file and the field for anything else or anything inconsistent.
Ktx2Texture read_ktx2(const std::string& path);

// IEEE 754 binary16 conversions (round to nearest even), as the file stores the values.
uint16_t to_half(float f);
float from_half(uint16_t h);

}  // namespace ibl::engine
