// A pinhole "photograph" of a lab scene: what a camera would see, with every pixel the mean of n×n
// stratified rays through it, each carrying lab::radiance (direct light with shadow rays, optional
// bounces). It is the reference the renderers are compared against: put an object into the scene
// (add_object), photograph it, and render the same object lit by a captured representation
// (Löw et al. 2009, Fig. 9: a photograph beside renderings from SH grids of 8³…64³).
#pragma once
#include <functional>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/lab/scene.h"

namespace ibl::lab {

// Primary ray through continuous pixel position (px, py) (y down): origin and unit direction.
using PixelRayFn = std::function<void(double px, double py, Vec3* origin, Vec3* direction)>;

struct ViewDesc {
  int width = 640, height = 480;  // pixels
  int samples = 4;                // n: n×n stratified rays per pixel (antialiasing and light sampling)
  RenderDesc render;              // light estimation (area/environment samples, bounces, seed)
};

struct View {
  Image radiance;  // RGB, W/(sr·m²)
  Image surface;   // one channel: index into Scene::surfaces of the first hit at the pixel centre, −1 for none
};

View photograph(const Scene& scene, const PixelRayFn& ray, const ViewDesc& desc, const ProgressFn& progress = {});

// Adds a Lambertian object (not part of the proxy) to a scene that is not built yet; returns its
// surface index.
int add_object(Scene& scene, const std::string& name, geometry::TriMesh mesh, Vec3 albedo);

}  // namespace ibl::lab
