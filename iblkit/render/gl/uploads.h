// What the GL renderer keeps on the GPU between frames, and when it may: meshes and an SH grid's
// texture while their values stay (compared in full against copies), textured spotlights' textures
// while they are the same shared (immutable) images, the colour target while its size stays. A
// viewer's frame then costs comparisons and GPU work, not uploads. Needs a current context, which
// must outlive the Uploads.
#pragma once
#include <memory>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/nearfield/spotlight.h"
#include "iblkit/render/frame.h"

namespace ibl::render::gl {

// A mesh's vertex array: positions, normals, UVs (zeros where the mesh has none) and indices.
struct MeshBuffers {
  unsigned vao = 0, vbo[3] = {0, 0, 0}, ebo = 0;
  int count = 0;  // indices
};

class Uploads {
 public:
  Uploads() = default;
  ~Uploads();
  Uploads(const Uploads&) = delete;
  Uploads& operator=(const Uploads&) = delete;

  // The colour target (RGBA32F), recreated when the size changes; last_color_texture() is the one
  // the last frame went to (0 before any).
  unsigned color_texture(int width, int height);
  unsigned last_color_texture() const { return color_tex_; }

  // The objects' vertex arrays and, with `deferred`, all objects' geometry in storage buffers for
  // the compute pass (object table {first vertex, first index, 0, 0}, positions, normals, indices,
  // UVs).
  struct Geometry {
    std::vector<Mesh> keys;
    std::vector<MeshBuffers> meshes;
    unsigned ssbo[5] = {0, 0, 0, 0, 0};
    void release();
  };
  const Geometry& geometry(const std::vector<RenderObject>& objects, bool deferred);

  // The SH grid in one RGBA16F 3D texture, coefficient k in slices [k·nz, (k+1)·nz).
  unsigned grid_texture(const ilf::SHGrid& grid);

  // The spotlights' textures in one mip-mapped RGBA16F 2D array, a layer per spotlight, each
  // divided by its largest |texel| (`scale`: half floats stop at 65504).
  struct SpotTextures {
    std::vector<std::shared_ptr<const std::vector<Image>>> keys;
    unsigned tex = 0;
    int levels = 0;
    std::vector<float> scale;
  };
  const SpotTextures& spot_textures(const std::vector<nearfield::TexturedSpotlight>& lights);

 private:
  unsigned color_tex_ = 0;
  int color_w_ = 0, color_h_ = 0;
  Geometry geometry_;
  unsigned grid_tex_ = 0;
  ilf::SHGrid grid_key_;
  SpotTextures spots_;
};

}  // namespace ibl::render::gl
