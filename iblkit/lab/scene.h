// A lab scene: Lambertian surfaces (constant or textured albedo, optional emission) and emitters
// (area lights, spotlights, projectors, point lights, a distant environment), ray traced with
// Embree. Scenes come from iblkit.scene/1 JSON files (scene_io.h, docs/formats.md) or are built
// in code (tests). Units: metres; radiance in W/(sr·m²); intensity in W/sr; linear Rec.709 RGB.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"
#include "iblkit/geometry/mesh.h"
#include "iblkit/geometry/raytracer.h"
#include "iblkit/geometry/surface.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::lab {

// Albedo of a surface: constant, an image indexed by UV, or a procedural checker.
struct Texture {
  Vec3 constant{0.5, 0.5, 0.5};             // used when there is no image and no checker
  std::shared_ptr<Image> image;             // RGB, looked up at (u·scale.x, 1 − v·scale.y), repeating
  Vec2 scale{1, 1};                         // texture repeats across the UV square
  bool checker = false;                     // a checker of `tiles` squares per UV unit in colours a and b
  Vec3 a{0.8, 0.8, 0.8}, b{0.2, 0.2, 0.2};  // checker colours
  Vec2 tiles{8, 8};                         // checker squares along u and v
  Vec3 eval(Vec2 uv) const;
};

enum class SurfaceRole {
  Diffuse,    // a Lambertian reflector (optionally also a uniform emitter)
  AreaLight,  // the emitting face of an area light (black, emits `emitters[emitter].radiance`)
  Aperture,   // the emitting disc of a spotlight or projector (radiance follows its beam)
};

struct Surface {
  std::string name;                         // for messages and the docs
  geometry::TriMesh mesh;                   // world-space triangles
  Texture albedo;                           // diffuse reflectance in [0,1]
  Vec3 emission{0, 0, 0};                   // uniform radiance leaving the front side (not light-sampled)
  SurfaceRole role = SurfaceRole::Diffuse;  // what a hit means
  int emitter = -1;                         // the emitter this surface belongs to (lights and apertures)
  bool proxy = true;                        // part of the exported proxy mesh (walls, fixed furniture)
  std::vector<Vec3> normals;                // per-triangle front normals (filled by Scene::build)
};

enum class EmitterType { Area, Spot, Projector, Point, Environment };

// Built-in projector patterns (a projector may also take an image file).
enum class Pattern { Image, Squares, Checker, White, Disc };

struct Emitter {
  EmitterType type = EmitterType::Point;
  std::string name;  // for messages
  // Area lights (quad or disc, emitting from the front, uniform radiance).
  bool disc = false;                           // disc (true) or quad (false)
  Vec3 center, normal{0, -1, 0}, up{0, 0, 1};  // placement; quad's height runs along `up`
  Vec2 size{1, 1};                             // quad width × height, metres
  double radius = 0.5;                         // disc radius, metres
  Vec3 radiance{1, 1, 1};                      // area lights: W/(sr·m²); environment: constant radiance
  // Point, spot and projector lights.
  Vec3 position;                       // the lamp's centre, metres
  Vec3 direction{0, -1, 0};            // beam axis (unit)
  Vec3 intensity{1, 1, 1};             // radiant intensity on the axis, W/sr (colour × intensity)
  double cone_deg = 30;                // spot: half-angle where the beam ends
  double falloff_deg = 25;             // spot: half-angle where the fall-off starts (full inside)
  double aperture_radius = 0.025;      // spot/projector: radius of the visible emitting disc, metres
  Vec2 fov_deg{40, 40};                // projector: full horizontal and vertical field of view
  Pattern pattern = Pattern::Squares;  // projector: what it projects
  std::shared_ptr<Image> image;        // projector pattern image (Pattern::Image)
  // Environment (distant light).
  std::shared_ptr<sphere::EnvMap> env;  // radiance map; absent: constant `radiance`
  Mat3 rotation;                        // environment frame -> world
  double scale = 1;                     // multiplies the environment's radiance
  double emit_area = 0;                 // area of the emitting geometry, m² (filled by Scene::build)

  // Radiant intensity (W/sr) a point-like lamp sends along unit direction w (world).
  Vec3 intensity_towards(Vec3 w) const;
  // Environment radiance arriving from unit direction d (travelling along −d).
  Vec3 environment(Vec3 d) const;
  // Right/up/forward frame of a spot or projector.
  Frame beam_frame() const;
  // Normalises the placement and caches what every light query needs (Scene::build calls it).
  void prepare();

  // Cached by prepare(): beam frame, cone cosines, projector tangents, area light edge directions.
  Frame frame;
  double cos_cone = 0, cos_falloff = 1, tan_x = 1, tan_y = 1;
  Vec3 edge_u, edge_v;
};

// How light is estimated; a scene file's "settings" fill it, the CLI can override.
struct RenderDesc {
  int area_samples = 4;  // shadow rays per area light per diffuse hit (stratified when square)
  int env_samples = 16;  // cosine-distributed shadow rays towards the environment per diffuse hit
  int bounces = 0;       // indirect bounces (0: direct light only)
  uint64_t seed = 1;     // base of every random stream
};

class Scene {
 public:
  std::string name;                                             // scene name ("low-scene1")
  std::string description;                                      // one line for listings
  std::string source;                                           // the file it came from (empty when built in code)
  std::vector<Surface> surfaces;                                // index = ray tracer mesh index after build()
  std::vector<Emitter> emitters;                                // lights
  RenderDesc render;                                            // defaults from the file's "settings"
  Vec3 volume_min{-0.5, 0.5, -0.5}, volume_max{0.5, 1.5, 0.5};  // the capture volume
  std::string proxy_file;  // a proxy mesh file given by the scene (empty: export the proxy surfaces)

  // Adds emitting geometry for area lights and apertures, computes normals and builds the BVH.
  // Call once, after filling surfaces and emitters.
  void build();
  bool built() const { return tracer_ != nullptr; }
  const geometry::RayTracer& tracer() const { return *tracer_; }
  // The environment emitter, or null.
  const Emitter* environment() const { return env_index_ < 0 ? nullptr : &emitters[env_index_]; }
  // The proxy mesh: the proxy file when given, else every surface marked proxy.
  geometry::TriMesh proxy_mesh() const;

 private:
  std::shared_ptr<geometry::RayTracer> tracer_;
  int env_index_ = -1;
};

// The scene's Lambertian reflectors (role Diffuse; emitters' geometry left out) as plain geometry with
// their albedo: how a renderer outside the lab (nearfield::SceneView) sees a lab scene.
std::vector<geometry::DiffuseSurface> diffuse_surfaces(const Scene& scene);

}  // namespace ibl::lab
