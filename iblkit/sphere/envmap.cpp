#include "iblkit/sphere/envmap.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "iblkit/core/error.h"
#include "iblkit/core/fastmath.h"
#include "iblkit/core/parallel.h"

#include <tbb/enumerable_thread_specific.h>

namespace ibl::sphere {

EnvMap::EnvMap(Image img, Mapping m) : image(std::move(img)), mapping(m) {
  if (image.width() != mapping.width() || image.height() != mapping.height())
    fail(ErrorKind::Value, "image is {}x{} but its {} mapping is {}x{}", image.width(), image.height(),
         mapping_name(mapping.kind()), mapping.width(), mapping.height());
}

EnvMap EnvMap::from_image(Image img, std::optional<MappingKind> kind, std::string_view name, double dead_angle_deg) {
  MappingKind k = kind ? *kind : detect_mapping(img.width(), img.height(), name);
  if (k == MappingKind::CubeHCross && img.width() * 4 == img.height() * 3) k = MappingKind::CubeVCross;
  Mapping m(k, img.width(), img.height(), dead_angle_deg);
  return EnvMap(std::move(img), m);
}

void EnvMap::sample(Vec3 d, float* out) const {
  double px, py;
  int nc = image.channels();
  if (!mapping.to_pixel(d, &px, &py)) {
    for (int c = 0; c < nc; ++c) out[c] = 0.0f;
    return;
  }
  ImageView v = image.view();
  switch (mapping.kind()) {
    case MappingKind::LatLong:
      v.bilinear(px, py, Wrap::LatLong, out);
      return;
    case MappingKind::CubeHCross:
    case MappingKind::CubeVCross:
    case MappingKind::CubeStrip: {
      int f = mapping.face_size();
      int cx = static_cast<int>(px) / f, cy = static_cast<int>(py) / f;
      v.sub(cx * f, cy * f, f, f).bilinear(px - cx * f, py - cy * f, Wrap::Clamp, out);
      return;
    }
    default:
      v.bilinear(px, py, Wrap::Clamp, out);
      return;
  }
}

Vec3 EnvMap::sample_rgb(Vec3 d) const {
  float buf[64];
  sample(d, buf);
  return image.channels() >= 3 ? Vec3{buf[0], buf[1], buf[2]} : Vec3{buf[0], buf[0], buf[0]};
}

std::vector<double> EnvMap::integral() const {
  int nc = image.channels();
  std::vector<double> sum(nc, 0.0);
  std::vector<std::vector<double>> rows(image.height(), std::vector<double>(nc, 0.0));
  parallel_for(0, image.height(), [&](int64_t y) {
    for (int x = 0; x < image.width(); ++x) {
      if (!mapping.valid(x, static_cast<int>(y))) continue;
      double w = mapping.solid_angle(x, static_cast<int>(y));
      const float* p = image.pixel(x, static_cast<int>(y));
      for (int c = 0; c < nc; ++c) rows[y][c] += w * p[c];
    }
  });
  for (auto& r : rows)
    for (int c = 0; c < nc; ++c) sum[c] += r[c];
  return sum;
}

Image solid_angle_image(const Mapping& m) {
  Image out(m.width(), m.height(), 1);
  parallel_for(0, m.height(), [&](int64_t y) {
    for (int x = 0; x < m.width(); ++x)
      out.at(x, static_cast<int>(y), 0) =
          m.valid(x, static_cast<int>(y)) ? static_cast<float>(m.solid_angle(x, static_cast<int>(y))) : 0.0f;
  });
  return out;
}

namespace {

// Bilinear lookup in a lat-long image for a batch of directions, in float: the (u,v) of every
// direction first, in a loop that vectorises (fast_atan2), then the gathers. The hot path of
// most conversions.
// kNc > 0 fixes the channel count at compile time (the common RGB case); 0 reads it from the image.
template <int kNc>
// `rows[y]` points at row y's pixels (the image's own, or a pole-filtered copy).
void latlong_lookup_batch(const Image& img, const float* const* rows, const float* dx, const float* dy, const float* dz,
                          int count, float* u_buf, float* v_buf, float* out) {
  constexpr float kInv2Pi = 0.159154943091895f, kInvPi = 0.318309886183791f;
  const float fw = static_cast<float>(img.width()), fh = static_cast<float>(img.height());
  for (int k = 0; k < count; ++k) {
    float x = dx[k], y = dy[k], z = dz[k];
    u_buf[k] = (fast_atan2(z, x) * kInv2Pi + 0.5f) * fw - 0.5f;
    v_buf[k] = fast_atan2(std::sqrt(x * x + z * z), y) * kInvPi * fh - 0.5f;
  }
  const int w = img.width(), h = img.height();
  const int nc = kNc > 0 ? kNc : img.channels();
  for (int k = 0; k < count; ++k) {
    float px = u_buf[k], py = v_buf[k];
    float x0f = std::floor(px), y0f = std::floor(py);
    float tx = px - x0f, ty = py - y0f;
    int x0 = static_cast<int>(x0f), y0 = static_cast<int>(y0f);
    int xa = x0 < 0 ? x0 + w : (x0 >= w ? x0 - w : x0);
    int xb = x0 + 1 >= w ? x0 + 1 - w : x0 + 1;
    int ya = std::clamp(y0, 0, h - 1), yb = std::clamp(y0 + 1, 0, h - 1);
    const float* p00 = rows[ya] + xa * nc;
    const float* p10 = rows[ya] + xb * nc;
    const float* p01 = rows[yb] + xa * nc;
    const float* p11 = rows[yb] + xb * nc;
    float w00 = (1 - tx) * (1 - ty), w10 = tx * (1 - ty), w01 = (1 - tx) * ty, w11 = tx * ty;
    float* o = out + static_cast<size_t>(k) * nc;
    for (int c = 0; c < nc; ++c) o[c] = w00 * p00[c] + w10 * p10[c] + w01 * p01[c] + w11 * p11[c];
  }
}

// Sub-samples along one output-pixel axis whose step moves `extent` input pixels. Point samples of
// the bilinear tent at a non-integer spacing h miss or double-count part of an isolated bright
// pixel's power (up to 12% at h = 0.75, none at h = 1/k), so samples stay no further apart than
// about kSpacing input pixels. Measured on blender-data's night.exr, whose single 7000-nit lamp
// pixel holds much of its power: this keeps round trips through every mapping within 0.5%.
int supersampling(double extent, int max_n) {
  constexpr double kSpacing = 0.6;
  return std::clamp(static_cast<int>(std::ceil(extent / kSpacing - 0.25)), 1, max_n);
}

// Distance in input pixels between two input positions, across the lat-long seam if shorter.
double pixel_distance(const Mapping& m, double ax, double ay, double bx, double by, double u_scale = 1.0) {
  double dx = std::abs(ax - bx), dy = std::abs(ay - by);
  if (m.kind() == MappingKind::LatLong) dx = std::min(dx, m.width() - dx);
  dx *= u_scale;
  return std::sqrt(dx * dx + dy * dy);
}

// Lat-long rows near the poles hold many narrow pixels: row y is box-filtered along u over
// k(y) = ⌊1/sin θ⌋ pixels (wrapping), so that sampling it needs only ~1/k(y) as many sub-samples
// across. Every pixel of a row has the same solid angle, so each row's ∫L dω is unchanged.
int pole_filter_width(int y, int height) {
  double st = std::sin(kPi * (y + 0.5) / height);
  return std::max(1, static_cast<int>(std::floor(1.0 / std::max(st, 1e-3))));
}

// Row pointers of the lookup image: the source's rows, except polar rows, which point into
// `storage` where they are box-filtered along u.
std::vector<const float*> prefilter_poles(const Image& src, std::vector<float>* storage) {
  const int W = src.width(), H = src.height(), nc = src.channels();
  std::vector<const float*> rows(H);
  std::vector<size_t> offset(H, 0);
  size_t need = 0;
  for (int y = 0; y < H; ++y)
    if (std::min(pole_filter_width(y, H), W) > 1) {
      offset[y] = need;
      need += static_cast<size_t>(W) * nc;
    }
  storage->resize(need);
  for (int y = 0; y < H; ++y)
    rows[y] = std::min(pole_filter_width(y, H), W) > 1 ? storage->data() + offset[y] : src.pixel(0, y);
  parallel_for(0, H, [&](int64_t yy) {
    int y = static_cast<int>(yy);
    int k = std::min(pole_filter_width(y, H), W);
    if (k <= 1) return;
    const float* in = src.pixel(0, y);
    float* o = storage->data() + offset[y];
    std::vector<double> acc(nc, 0.0);
    int lo = -(k / 2);  // window [x + lo, x + lo + k)
    for (int i = lo; i < lo + k; ++i)
      for (int c = 0; c < nc; ++c) acc[c] += in[((i % W + W) % W) * nc + c];
    for (int x = 0; x < W; ++x) {
      // The running sum can round a little below zero where the row is black; inputs are ≥ 0.
      for (int c = 0; c < nc; ++c) o[x * nc + c] = static_cast<float>(std::max(0.0, acc[c] / k));
      int out_i = ((x + lo) % W + W) % W, in_i = ((x + lo + k) % W + W) % W;
      for (int c = 0; c < nc; ++c) acc[c] += in[in_i * nc + c] - in[out_i * nc + c];
    }
  });
  return rows;
}

// Pass 3 of resample(): each output pixel of row y is the mean of its sub-samples (`owner`, ascending).
void average_by_owner(const float* vals, const int* owner, int count, int nc, Image* out, int y) {
  if (nc == 3) {
    for (int k = 0; k < count;) {
      int x = owner[k], m = 0;
      float a0 = 0, a1 = 0, a2 = 0;
      for (; k < count && owner[k] == x; ++k, ++m) {
        const float* v = vals + static_cast<size_t>(k) * 3;
        a0 += v[0];
        a1 += v[1];
        a2 += v[2];
      }
      float* o = out->pixel(x, y);
      float inv_m = 1.0f / m;
      o[0] = a0 * inv_m;
      o[1] = a1 * inv_m;
      o[2] = a2 * inv_m;
    }
    return;
  }
  std::vector<float> acc(static_cast<size_t>(nc));
  for (int k = 0; k < count;) {
    int x = owner[k], m = 0;
    std::fill(acc.begin(), acc.end(), 0.0f);
    for (; k < count && owner[k] == x; ++k, ++m)
      for (int c = 0; c < nc; ++c) acc[static_cast<size_t>(c)] += vals[static_cast<size_t>(k) * nc + c];
    float* o = out->pixel(x, y);
    for (int c = 0; c < nc; ++c) o[c] = acc[static_cast<size_t>(c)] / m;
  }
}

}  // namespace

Image resample(const EnvMap& src, const Mapping& dst, const ResampleDesc& desc) {
  int nc = src.image.channels();
  Image out(dst.width(), dst.height(), nc);
  bool rotate = false;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rotate |= std::abs(desc.rotation.m[i][j] - (i == j ? 1.0 : 0.0)) > 0;
  Mat3 inv = desc.rotation.transposed();
  bool fast = src.mapping.kind() == MappingKind::LatLong;
  // Lat-long sources: look up a copy whose polar rows are filtered along u (prefilter_poles).
  std::vector<float> pole_rows;
  std::vector<const float*> rows;
  if (fast) rows = prefilter_poles(src.image, &pole_rows);
  bool cube_dst = dst.kind() == MappingKind::CubeHCross || dst.kind() == MappingKind::CubeVCross ||
                  dst.kind() == MappingKind::CubeStrip;
  struct RowBuffers {
    std::vector<float> dx, dy, dz, vals, ub, vb;
    std::vector<int> owner;
  };
  tbb::enumerable_thread_specific<RowBuffers> buffers;
  std::atomic<int64_t> rows_done{0};
  parallel_for(0, dst.height(), [&](int64_t yy) {
    int y = static_cast<int>(yy);
    report(desc.progress, "resample", double(rows_done++) / dst.height());
    // Pass 1: the row's sub-sample directions; pass 2: look them all up; pass 3: average.
    RowBuffers& rb = buffers.local();
    std::vector<float>&dx = rb.dx, &dy = rb.dy, &dz = rb.dz;
    std::vector<int>& owner = rb.owner;
    const size_t most = static_cast<size_t>(dst.width()) * desc.max_supersampling * desc.max_supersampling;
    if (dx.size() < most) {
      dx.resize(most);
      dy.resize(most);
      dz.resize(most);
      owner.resize(most);
    }
    int count = 0;
    int nx = 1, ny = 1, footprint_at = -1000;
    for (int x = 0; x < dst.width(); ++x) {
      Vec3 c;
      int face = -1;
      bool rot = false;
      if (cube_dst) {
        if (!dst.cube_cell(x, y, &face, &rot)) continue;
      } else if (!dst.to_direction(x + 0.5, y + 0.5, &c)) {
        continue;
      }
      // The output pixel's footprint in the input: where its centre and its two neighbours land.
      // It changes slowly, so it is measured every kFootprintStride pixels.
      constexpr int kFootprintStride = 8;
      if (x - footprint_at >= kFootprintStride) {
        if (cube_dst) dst.to_direction(x + 0.5, y + 0.5, &c);
        footprint_at = x;
        Vec3 cx, cy;
        bool okx = dst.to_direction(x + 1.5, y + 0.5, &cx) || dst.to_direction(x - 0.5, y + 0.5, &cx);
        bool oky = dst.to_direction(x + 0.5, y + 1.5, &cy) || dst.to_direction(x + 0.5, y - 0.5, &cy);
        Vec3 cc = c;
        if (rotate) {
          cc = inv * cc;
          cx = inv * cx;
          cy = inv * cy;
        }
        double p0x, p0y, p1x, p1y, p2x, p2y;
        src.mapping.to_pixel(cc, &p0x, &p0y);
        src.mapping.to_pixel(cx, &p1x, &p1y);
        src.mapping.to_pixel(cy, &p2x, &p2y);
        double u_scale = fast ? 1.0 / pole_filter_width(std::clamp(static_cast<int>(p0y), 0, src.mapping.height() - 1),
                                                        src.mapping.height())
                              : 1.0;
        nx = okx ? supersampling(pixel_distance(src.mapping, p0x, p0y, p1x, p1y, u_scale), desc.max_supersampling) : 1;
        ny = oky ? supersampling(pixel_distance(src.mapping, p0x, p0y, p2x, p2y, u_scale), desc.max_supersampling) : 1;
      }
      if (cube_dst && !rotate) {
        // Cube faces: the sub-sample directions straight from the face's (s, t), in float:
        // point = centre + s·ds + t·dt with the face's axes (cube_face_point is linear in s, t).
        const int F = dst.face_size();
        const float inv_f = 2.0f / F;
        const float s0 = (static_cast<float>(x % F) + 0.5f / nx) * inv_f - 1.0f, sd = inv_f / nx;
        const float t0 = (static_cast<float>(y % F) + 0.5f / ny) * inv_f - 1.0f, td = inv_f / ny;
        const Vec3 c0 = cube_face_point(face, 0, 0), cs = cube_face_point(face, 1, 0) - c0,
                   ct = cube_face_point(face, 0, 1) - c0;
        const float sign = rot ? -1.0f : 1.0f;  // vcross −Z is turned 180°: (s, t) → (−s, −t)
        const float ax = static_cast<float>(c0.x), ay = static_cast<float>(c0.y), az = static_cast<float>(c0.z);
        const float sx = sign * static_cast<float>(cs.x), sy = sign * static_cast<float>(cs.y),
                    sz = sign * static_cast<float>(cs.z);
        const float tx = sign * static_cast<float>(ct.x), ty = sign * static_cast<float>(ct.y),
                    tz = sign * static_cast<float>(ct.z);
        for (int j = 0; j < ny; ++j) {
          const float t = t0 + j * td;
          for (int i = 0; i < nx; ++i) {
            const float sv = s0 + i * sd;
            float px = ax + sv * sx + t * tx, py = ay + sv * sy + t * ty, pz = az + sv * sz + t * tz;
            // The lat-long lookup needs no unit vector (both of its angles are scale-free).
            float inv_len = fast ? 1.0f : 1.0f / std::sqrt(px * px + py * py + pz * pz);
            dx[count] = px * inv_len;
            dy[count] = py * inv_len;
            dz[count] = pz * inv_len;
            owner[count++] = x;
          }
        }
        continue;
      }
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          Vec3 d;
          if (!dst.to_direction(x + (i + 0.5) / nx, y + (j + 0.5) / ny, &d)) continue;
          if (rotate) d = inv * d;
          dx[count] = static_cast<float>(d.x);
          dy[count] = static_cast<float>(d.y);
          dz[count] = static_cast<float>(d.z);
          owner[count++] = x;
        }
    }
    std::vector<float>&vals = rb.vals, &ub = rb.ub, &vb = rb.vb;
    vals.resize(static_cast<size_t>(count) * nc);
    ub.resize(count);
    vb.resize(count);
    if (fast) {
      if (nc == 3)
        latlong_lookup_batch<3>(src.image, rows.data(), dx.data(), dy.data(), dz.data(), count, ub.data(), vb.data(),
                                vals.data());
      else
        latlong_lookup_batch<0>(src.image, rows.data(), dx.data(), dy.data(), dz.data(), count, ub.data(), vb.data(),
                                vals.data());
    } else {
      for (int k = 0; k < count; ++k) src.sample({dx[k], dy[k], dz[k]}, vals.data() + static_cast<size_t>(k) * nc);
    }
    average_by_owner(vals.data(), owner.data(), count, nc, &out, y);
  });
  return out;
}

}  // namespace ibl::sphere
