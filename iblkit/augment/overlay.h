// The proxy drawn over the photograph as the camera sees it (`composite --layers`: proxy_overlay.png): the
// quick look that tells a user whether the camera — its pose and its lens — and the proxy agree. The proxy's
// feature edges (a boundary, or between triangles whose normals differ by more than 20°: a flat floor's
// diagonals are not drawn) are sampled about every pixel, projected through the camera (Camera::project,
// distortion included), and drawn where the camera sees them: a sample behind another part of the proxy is
// left out.
#pragma once
#include "iblkit/core/image.h"
#include "iblkit/geometry/camera.h"
#include "iblkit/geometry/mesh.h"

namespace ibl::augment {

// picture: RGB in [0, 1] (the photograph tone mapped), the camera's size. Throws ibl::Error on sizes that
// disagree.
Image proxy_overlay(const Image& picture, const geometry::Camera& cam, const geometry::TriMesh& proxy,
                    Vec3 rgb = {0.15, 1.0, 0.3});

}  // namespace ibl::augment
