// The captured light of a local scene, as a composite uses it: a radiance map seen from one point (a
// probe at its position, an SH grid or fused probes evaluated at the object) projected onto the proxy
// (Debevec 1998, §4: the light-based model of the local scene). Every texel becomes a patch — the
// proxy surface it sees (or a direction, where its ray leaves the proxy) with the texel's radiance —
// so the light arriving at any point x of the local scene is a sum over patches:
//
//   E(x, n) = Σ_t L_t · Ω_t(x) · max(0, n·ω_t(x)) · V(x, q_t),     Ω_t(x) = A_t cos θ_q / |q_t − x|²
//
// A_t = Ω_t r_t² / cos θ_c, the patch's area (r_t its distance from the map's centre c, θ_c the angle its
// normal makes with the way back to c), so that Ω_t(c) = Ω_t; a distant patch keeps Ω_t for every x.
// Estimates sample patches in proportion to a mix of their power and their solid angle (seen from c); a
// receiver whose normal is one of the proxy's main ones (a floor, a wall) samples from a table conditioned on
// it, which leaves out the patches its side cannot see (sky below its horizon, the floor it lies on).
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/image.h"
#include "iblkit/core/vec.h"
#include "iblkit/fusion/probe_set.h"
#include "iblkit/geometry/raytracer.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/sphere/envmap.h"

namespace ibl::augment {

// The radiance arriving at one point of the local scene (`centre`), as a lat-long map, with the optional
// depth of what each texel sees: the captured light a composite uses (from a probe, an SH grid or fused
// probes). A map, not a light: LightField below turns it into the patches that light the proxy.
struct LocalRadiance {
  sphere::EnvMap map{Image(2, 1, 3),
                     sphere::Mapping(sphere::MappingKind::LatLong, 2, 1)};  // radiance arriving at centre
  Vec3 centre;                                                              // where the map was taken, world metres
  Image depth;         // optional, 1 channel, the map's size: metres from centre to what each texel sees (0: none)
  std::string source;  // "probe", "SH grid", "fused probes": for messages
};

// The grid's radiance at `at` as a lat-long map of 2·size × size: Hanning-windowed, negative ringing clamped to
// 0, then scaled per channel to the grid's own power there (clamping alone adds light).
LocalRadiance light_from_grid(const ilf::SHGrid& grid, Vec3 at, int size = 64);
// The probe set fused at `at` (fusion::fuse, footprint blend) as a lat-long map of 2·size × size.
LocalRadiance light_from_probes(const fusion::ProbeSet& set, Vec3 at, int size = 128);

// A baseline: the light cut into `count` median-cut lights (lights::median_cut, Debevec 2005), each put into
// the one texel of its direction with all of its region's power (and that texel's depth): what a renderer
// with N shadow-casting lights sees. The map must be lat-long.
LocalRadiance as_median_cut(const LocalRadiance& light, int count);

// The light's patches on the proxy, and their sampling.
class LightField {
 public:
  // `proxy_tracer` holds `proxy` as its mesh 0 (and nothing else).
  LightField(const LocalRadiance& light, const geometry::TriMesh& proxy, const geometry::RayTracer& proxy_tracer);
  size_t size() const { return patches_.size(); }
  // The sampling table for a receiver with unit normal n: one conditioned on one of the proxy's main normals
  // (within 10°, either side; kept for the proxy's largest flat parts by area), or −1, the table for any normal.
  // A conditioned table is 70 % the plain table weighted by what a surface of that normal can see of each
  // patch — the cosine of a distant patch (none below its horizon), none of a patch on the proxy that faces the
  // same way (a floor does not see the floor), all of any other — and 30 % the plain one, so that no patch a
  // receiver within the 10° may see has probability 0 (the estimate stays unbiased).
  int table_for(Vec3 n) const;
  size_t tables() const { return tables_.size(); }
  // The patch a uniform u in [0, 1) picks from `table`, and the probability of picking it.
  size_t sample(double u, double* pmf, int table = -1) const;
  // L_t Ω_t(x) max(0, n·ω) of patch i at x with unit normal n (0 when either side faces away); *w the unit
  // direction towards it and *dist its distance (infinity for a distant patch).
  Vec3 contribution(size_t i, Vec3 x, Vec3 n, Vec3* w, double* dist, bool shadowed = false) const;
  // Whether patch i lies on the proxy (or a lamp in front of it) rather than at infinity, and where.
  bool local(size_t i) const { return !patches_[i].distant; }
  Vec3 point(size_t i) const { return patches_[i].point; }
  Vec3 normal(size_t i) const { return patches_[i].normal; }
  // The object's shadow on patch i as a factor of its radiance (1: untouched), for the light the object
  // receives from the proxy; contribution(…, shadowed = true) applies it.
  void set_shadow(size_t i, Vec3 factor) { patches_[i].shadow = factor; }
  // ∫ mean(R, G, B) dω over the map, W/m²: for messages and tests.
  double total_power() const { return total_; }

  // For estimators that sample directions themselves (multiple importance sampling with sample()):
  // the probability sample() picks patch i; its solid angle seen from x (0 when it faces away); whether it
  // is a free emitter (a lamp in front of the proxy, from the depth map) rather than the proxy or the sky.
  double pmf(size_t i, int table = -1) const {
    const std::vector<double>& c = table < 0 ? cdf_.cdf : tables_[static_cast<size_t>(table)].cdf;
    return c[i] - (i > 0 ? c[i - 1] : 0.0);
  }
  double solid_angle_at(size_t i, Vec3 x) const;
  bool lamp(size_t i) const { return patches_[i].lamp; }
  // The patch a ray from x along unit w sees first (the proxy hit's texel seen from the centre, when that texel's
  // patch is that surface; the map's texel of w where the ray leaves the proxy), or −1: the radiance the patches
  // give that ray, lamps left out. `proxy_tracer` as in the constructor.
  long patch_along(Vec3 x, Vec3 w, const geometry::RayTracer& proxy_tracer) const;
  // The same, given that ray's hit on the proxy (h.hit false: it leaves the proxy).
  long patch_along(Vec3 x, Vec3 w, const geometry::Hit& h) const;
  Vec3 radiance(size_t i) const { return patches_[i].radiance; }
  // Asks the CPU to fetch patch i's record (a hint; for estimators that draw patches ahead of using them).
  void prefetch(size_t i) const {
    const char* p = reinterpret_cast<const char*>(&patches_[i]);
    __builtin_prefetch(p);
    __builtin_prefetch(p + sizeof(Patch) - 1);
  }

 private:
  struct Patch {
    Vec3 point;        // world point on the proxy, or the unit direction of a distant patch
    Vec3 normal;       // facing the centre (local patches)
    Vec3 radiance;     // W/(sr·m²)
    double area = 0;   // local: m²; distant: solid angle, sr
    double omega = 0;  // solid angle seen from the centre, sr
    bool distant = false;
    bool lamp = false;     // placed by the depth map in front of the proxy
    long texel = 0;        // its texel, row-major
    Vec3 shadow{1, 1, 1};  // the object's shadow on it (set_shadow)
  };
  std::vector<Patch> patches_;
  sphere::Mapping mapping_{sphere::MappingKind::LatLong, 2, 1};
  Vec3 centre_;
  std::vector<long> texel_patch_;  // the patch of each texel (row-major), −1 for none
  // A CDF and its guide table (Chen & Asau 1974): guide[j] the first index whose CDF exceeds j/G, so that sample()
  // searches only [guide[j], guide[j + 1]] — the same index a search of the whole CDF finds.
  struct Cdf {
    std::vector<double> cdf;
    std::vector<uint32_t> guide;
    void build_guide();
    size_t find(double u) const;
  };
  Cdf cdf_;
  std::vector<Cdf> tables_;  // conditioned on table_normal_[k]
  std::vector<Vec3> table_normal_;
  double total_ = 0;
  void build_tables(const geometry::TriMesh& proxy);
};

}  // namespace ibl::augment
