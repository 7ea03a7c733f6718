// A light field known in closed form, for tests and benchmarks of the ILF pipeline: emitting spheres
// outside the capture volume and a distant environment, nothing inside the volume. The radiance along
// any ray is the first sphere it hits, else the environment — so probes anywhere and the exact SH at
// any point follow without a renderer. (The lab module's scenes, with occluders and ray tracing, are
// the realistic test; this one needs no geometry backend.)
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/progress.h"
#include "iblkit/ilf/sequence.h"
#include "iblkit/sh/coeffs.h"

namespace ibl::ilf {

struct EmittingSphere {
  Vec3 centre;    // world position, metres
  double radius;  // metres
  Vec3 radiance;  // uniform emitted radiance, RGB
};

struct AnalyticField {
  std::vector<EmittingSphere> spheres;  // must not intersect the capture volume
  Vec3 sky_zenith{0.3, 0.4, 0.6};       // environment radiance towards +Y
  Vec3 sky_horizon{0.5, 0.5, 0.5};      // environment radiance at the horizon (and below, ground = ½ of it)

  // The default test scene: a 1 m cube at the origin lit by three coloured spheres and the sky.
  static AnalyticField three_spheres();
  // The same spheres scaled `factor` times further away (same angular size from the origin): a
  // nearly parallax-free field, whose SH hardly varies over the volume.
  static AnalyticField distant(double factor = 1000.0);
  Vec3 radiance(Vec3 x, Vec3 w) const;
  // A probe of the field at x, in `seq`'s mapping, dead angle and rotation, of width × height.
  Image render_probe(const Sequence& seq, int width, int height, Vec3 x, int supersample = 1) const;
  // Exact SH of L(x, ·) at each of xs by quadrature on a lat-long of 2n × n cells with exact solid
  // angles, ss × ss sub-samples per cell (the sphere edges make plain point sampling alias);
  // directions in the mirror ball's dead angle (probe frame −Z within dead_angle_deg) count zero,
  // as they do in the resampled grid.
  std::vector<sh::Coeffs> exact_sh(const std::vector<Vec3>& xs, int bands, const Sequence& seq, int n = 128,
                                   int ss = 2) const;
};

struct SynthDesc {
  std::string out_dir;          // folder for frames/ and sequence.json (created)
  int probes = 200;             // number of probes
  int size = 64;                // frame width = height (mirror ball)
  int supersample = 3;          // ss × ss sub-samples per pixel (a camera integrates over its pixels)
  double dead_angle_deg = 4.2;  // mirror-ball dead angle
  uint64_t seed = 1;            // random positions
  bool half = true;             // frames as half-float EXR (else float PFM)
  Box volume{{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}};  // positions are uniform random in it
};

// Writes a synthetic mirror-ball sequence of the field; returns the manifest path.
std::string write_synthetic_sequence(const AnalyticField& f, const SynthDesc& desc, const ProgressFn& progress = {});

}  // namespace ibl::ilf
