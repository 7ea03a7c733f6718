#include "render_setup.h"

#include "cli.h"
#ifdef IBLKIT_HAVE_GEOMETRY
#include <fmt/format.h>

#include "iblkit/core/error.h"
#include "iblkit/geometry/camera_io.h"
#include "iblkit/io/image_io.h"
#include "iblkit/render/objects.h"

namespace iblcli {

void add_shadow_map_options(CLI::App& app, ShadowMapOptions* o) {
  app.add_option("--shadow-map", o->size, "GL: shadow map size of each directional or point light (cube faces too)")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  app.add_option("--spot-shadow-map", o->spot_size,
                 "GL: shadow map size of each textured spotlight (a 9×7 dataset draws 63 of them a frame)")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  app.add_option("--spot-shadow-share", o->spot_share,
                 "GL: textured spotlights within this many metres of each other share one shadow map (0: one each)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
}

std::string grid_bounds_warning(const ibl::render::Lighting& L, const ibl::geometry::TriMesh& object) {
  if (!ibl::render::reaches_outside_grid(L, object)) return {};
  ibl::Vec3 lo, hi;
  object.bounds(&lo, &hi);
  const ibl::Vec3 gmin = L.grid->grid().volume.min, gmax = L.grid->grid().volume.max;
  return fmt::format(
      "the object spans ({:.3g}, {:.3g}, {:.3g})..({:.3g}, {:.3g}, {:.3g}), outside the SH grid's volume "
      "({:.3g}, {:.3g}, {:.3g})..({:.3g}, {:.3g}, {:.3g}): lookups there clamp to the grid's faces "
      "(move it with --at, shrink it with --object-size)",
      lo.x, lo.y, lo.z, hi.x, hi.y, hi.z, gmin.x, gmin.y, gmin.z, gmax.x, gmax.y, gmax.z);
}

ibl::render::ObjectDesc inserted_object(const std::string& kind, double size, int triangles, const std::string& at) {
  return {kind, size, triangles, parse_vec3(at, "--at")};
}

ibl::render::Material object_material(const std::string& albedo, double gloss, double exponent, const std::string& lobe,
                                      const std::string& texture) {
  using ibl::render::Lobe;
  ibl::render::Material m{parse_vec3(albedo, "--albedo"), ibl::Vec3{1, 1, 1} * gloss, exponent,
                          lobe == "blinn" ? Lobe::BlinnPhong : Lobe::Phong};
  if (!texture.empty()) {
    m.albedo = {1, 1, 1};
    m.texture = std::make_shared<ibl::Image>(ibl::io::read_image(texture).with_channels(3));
  }
  return m;
}

void add_photo_scene_options(CLI::App& app, PhotoSceneOptions* o, const std::string& prefix) {
  app.add_option("--eye", o->eye, prefix + "the photograph's camera position x,y,z");
  app.add_option("--target", o->target, prefix + "the point at the photograph's centre");
  app.add_option("--up", o->up, prefix + "the world direction that appears upwards")->capture_default_str();
  app.add_option("--fov", o->fov, prefix + "vertical field of view, degrees")->capture_default_str();
  app.add_option("--camera", o->camera, prefix + "an iblkit.camera/1 file instead of --eye/--target/--up/--fov");
  app.add_option(
      "--probes", o->probes,
      prefix + "an iblkit.probes/1 set with its proxy (one probe: Debevec 1998; several: fused at the object)");
  app.add_option(
      "--proxy", o->proxy,
      prefix + "the local scene's mesh (OBJ, PLY, glTF) with --light: receives shadows, occludes the object");
  app.add_option("--at-probe", o->at_probe, prefix + "where the --light probe was captured, x,y,z");
}

ibl::geometry::Camera photo_camera(const PhotoSceneOptions& o, const ibl::Image& photo, const std::string& photo_path,
                                   const std::string& who) {
  ibl::geometry::Camera cam;
  if (!o.camera.empty()) {
    if (!o.eye.empty() || !o.target.empty())
      ibl::fail(ibl::ErrorKind::Value, "give either --camera or --eye/--target, not both");
    cam = ibl::geometry::read_camera(o.camera);
    if ((cam.width != 0 && cam.width != photo.width()) || (cam.height != 0 && cam.height != photo.height()))
      ibl::fail(ibl::ErrorKind::Value, "{} is {}x{} but the photograph {} is {}x{}", o.camera, cam.width, cam.height,
                photo_path, photo.width(), photo.height());
  } else {
    if (o.eye.empty() || o.target.empty())
      ibl::fail(ibl::ErrorKind::Value, "{}give the photograph's camera: --eye and --target (and --fov), or --camera",
                who);
    cam.eye = parse_vec3(o.eye, "--eye");
    cam.target = parse_vec3(o.target, "--target");
    cam.up = parse_vec3(o.up, "--up");
    cam.fov_y_deg = o.fov;
  }
  cam.width = photo.width();
  cam.height = photo.height();
  ibl::geometry::validate_camera(cam, o.camera.empty() ? "the camera" : o.camera);
  return cam;
}

ibl::augment::LightInput photo_light_input(const PhotoSceneOptions& o, const std::vector<std::string>& light) {
  ibl::augment::LightInput li;
  li.probes = o.probes;
  if (!light.empty()) li.light = light[0];
  li.proxy = o.proxy;
  if (!o.at_probe.empty()) li.at_probe = parse_vec3(o.at_probe, "--at-probe");
  return li;
}

}  // namespace iblcli
#endif
