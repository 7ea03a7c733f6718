// Direction <-> pixel mappings of the sphere, with exact per-pixel solid angles.
// Conventions (docs/conventions.md):
//  - lat-long: θ = π v from +Y, u = atan2(d.z, d.x)/(2π) + 0.5, d = (−sinθ cos2πu, cosθ, −sinθ sin2πu).
//  - mirror ball: orthographic view of a chrome ball from +Z (camera looks along −Z); the disc fills the
//    image; the centre reflects +Z, the rim −Z; every pixel in the disc covers 4π/(π r²) sr per unit
//    area. Directions within `dead_angle` of −Z carry no data.
//  - angular map (Debevec): centre +Z, radius ∝ angle from +Z, rim −Z.
//  - cube faces +X −X +Y −Y +Z −Z with texel (s,t) ∈ [−1,1]², s right, t down:
//    +X (1,−t,−s), −X (−1,−t,s), +Y (s,1,t), −Y (s,−1,−t), +Z (s,−t,1), −Z (−s,−t,−1).
//    Layouts: horizontal cross 4:3 (+Y above +Z; −X +Z +X −Z in the middle row; −Y below),
//    vertical cross 3:4 (the same, with −Z below −Y, turned 180° so that it joins −Y), strip 6:1.
//  - octahedral: +Y at the centre of the square, −Y at the four corners.
// Pixel coordinates are continuous: pixel (x,y) covers [x,x+1) × [y,y+1), its centre is (x+½, y+½).
#pragma once
#include <optional>
#include <string>
#include <string_view>

#include "iblkit/core/vec.h"

namespace ibl::sphere {

enum class MappingKind { LatLong, MirrorBall, Angular, CubeHCross, CubeVCross, CubeStrip, Octahedral };

// Name used in files and on the command line: latlong, mirrorball, angular, hcross, vcross,
// cubestrip, octahedral. Parsing ignores case and also accepts "cubecross" (HCross; use
// detect_mapping to choose h/v by aspect) and a few aliases (equirect, ball, probe, cube).
std::string mapping_name(MappingKind k);
std::optional<MappingKind> find_mapping(std::string_view name);  // nullopt for an unknown name
// Throws ibl::Error "[what: ]unknown mapping 'x' (use latlong, …)" for an unknown name.
MappingKind parse_mapping(std::string_view name, std::string_view what = {});

// Cube faces in docs/conventions.md's order.
enum class CubeFace { PX = 0, NX, PY, NY, PZ, NZ };
// Direction through face texel (s,t) ∈ [−1,1]² (not normalised: the point on the unit cube).
Vec3 cube_face_point(int face, double s, double t);
// Face and (s,t) of a direction.
int cube_face_of(Vec3 d, double* s, double* t);

class Mapping {
 public:
  // dead_angle_deg applies to the mirror ball only.
  Mapping(MappingKind kind, int width, int height, double dead_angle_deg = 0.0);

  MappingKind kind() const { return kind_; }
  int width() const { return width_; }
  int height() const { return height_; }
  double dead_angle_deg() const { return dead_angle_deg_; }
  // Size of a cube face in pixels (cube layouts only).
  int face_size() const { return face_; }

  // Continuous pixel coordinates -> unit direction. False where the point carries no direction
  // (outside the disc, an unused cross cell) or no data (mirror-ball dead angle); d is still set
  // where a direction exists.
  bool to_direction(double px, double py, Vec3* d) const;
  // Unit direction -> continuous pixel coordinates. False when the direction has no data in this
  // mapping (mirror-ball dead angle).
  bool to_pixel(Vec3 d, double* px, double* py) const;

  // Exact solid angle of pixel (x,y), in steradians; 0 where the pixel covers no direction.
  // Σ over all pixels = 4π.
  double solid_angle(int x, int y) const;
  // Cheap estimate of solid_angle(x, y) (the Jacobian at the pixel centre × pixel area); 0 where
  // the pixel centre has no direction. For choosing sampling rates, not for integrals.
  double solid_angle_estimate(int x, int y) const;
  // True where the pixel centre carries data (inside the disc, a used cell, outside the dead angle).
  bool valid(int x, int y) const;

  // Cube layouts: the face under pixel (x, y) and whether its cell is turned 180° (vcross −Z);
  // false for an unused cell or a non-cube mapping.
  bool cube_cell(int x, int y, int* face, bool* rot180) const {
    if (face_ == 0 || x < 0 || y < 0 || x >= width_ || y >= height_) return false;
    return cell_face(x / face_, y / face_, face, rot180);
  }

  // Expected aspect ratio (width/height) of a layout: 2, 1, 4/3, 3/4, 6.
  static double aspect(MappingKind k);

 private:
  double disc_area(int x, int y) const;  // area of pixel ∩ disc, in units of the unit disc
  double angular_solid_angle(int x, int y) const;
  double octahedral_solid_angle(int x, int y) const;
  bool cell_face(int cx, int cy, int* face, bool* rot180) const;

  MappingKind kind_;
  int width_, height_;
  double dead_angle_deg_ = 0.0;
  double cos_dead_ = 2.0;  // a reflected direction with d.z < −cos_dead_ is in the dead angle
  int face_ = 0;
};

// Chooses a mapping from an image's shape, then from hints in its file name ("angular", "probe",
// "ball", "mirror", "oct"). Square images without a hint are mirror balls. Throws ibl::Error
// when the shape fits no mapping.
MappingKind detect_mapping(int width, int height, std::string_view file_name = {});

}  // namespace ibl::sphere
