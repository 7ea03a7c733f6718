// `iblkit demo` step "ilf": capture low-scene2 with the lab at demo size, build its SH grid at 8³,
// 16³ and 32³, and put irradiance slices through the middle of the volume side by side with the
// lab's ground truth (Löw et al. 2009, Fig. 9/11 as pictures). Builds without the geometry backend
// use the closed-form field of iblkit/ilf/analytic.h instead of the lab.
#include <filesystem>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/atomic_file.h"
#include "iblkit/core/parallel.h"
#include "iblkit/ilf/analytic.h"
#include "iblkit/ilf/build.h"
#include "iblkit/ilf/crossval.h"
#include "iblkit/io/draw.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"
#include "iblkit/sh/convolve.h"
#ifdef IBLKIT_HAVE_GEOMETRY
#include "iblkit/lab/scene_io.h"
#include "iblkit/lab/sequence.h"
#include "iblkit/lab/truth.h"
#endif

namespace {

namespace fs = std::filesystem;
using namespace ibl;

constexpr int kSlice =
    16;  // slices are kSlice² irradiance samples (the lab truth costs ~0.2 s a point; upscaled for display)

// Irradiance (normal +Y) on the plane y = middle of the volume, kSlice² points, x right, z down.
template <typename F>
Image slice(const ilf::Box& v, F&& irradiance_at) {
  Image img(kSlice, kSlice, 3);
  double y = v.centre().y;
  parallel_for(0, kSlice * kSlice, [&](int64_t i) {
    int px = int(i % kSlice), pz = int(i / kSlice);
    Vec3 p{v.min.x + v.size().x * (px + 0.5) / kSlice, y, v.min.z + v.size().z * (pz + 0.5) / kSlice};
    Vec3 e = irradiance_at(p);
    img.set_rgb(px, pz, {std::max(0.0, e.x), std::max(0.0, e.y), std::max(0.0, e.z)});
  });
  return img;
}

void ilf_step(iblcli::DemoContext& ctx) {
  fs::path dir = fs::path(ctx.out_dir) / "ilf";
  ibl::make_output_folders(fs::path(dir).string());
  std::string manifest;
  std::function<Vec3(Vec3)> truth;
  std::string scene_name;
#ifdef IBLKIT_HAVE_GEOMETRY
  auto scene = std::make_shared<lab::Scene>(lab::load_scene("low-scene2"));
  scene_name = "low-scene2";
  lab::SequenceDesc sd;
  sd.capture.mapping = sphere::MappingKind::MirrorBall;
  sd.capture.size = 48;
  sd.capture.samples = 4;  // 2×2 misses the projector's small aperture too often: 32³ error 0.73 vs 0.27
  sd.capture.dead_angle_deg = 4.2;
  sd.out_dir = (dir / "capture").string();
  sd.half = true;
  sd.sheet_probes = 0;
  auto pos = lab::random_positions(scene->volume_min, scene->volume_max, 1500, 5);
  manifest = lab::write_sequence(*scene, pos, sd).manifest;
  truth = [scene](Vec3 p) {
    lab::TruthDesc td;
    td.size = 80;  // the projector's aperture is small: coarser maps miss it (size 24 gives 0.06 W/m² for 30)
    td.samples = 2;
    td.area_samples = 16;
    td.bands = 0;
    td.normals = {{0, 1, 0}};
    return lab::ground_truth(*scene, p, td).irradiance[0];
  };
#else
  scene_name = "analytic three spheres";
  auto field = std::make_shared<ilf::AnalyticField>(ilf::AnalyticField::three_spheres());
  ilf::SynthDesc sd;
  sd.out_dir = (dir / "capture").string();
  sd.probes = 600;
  sd.size = 48;
  manifest = ilf::write_synthetic_sequence(*field, sd);
  auto seq0 = std::make_shared<ilf::Sequence>(ilf::read_sequence(manifest));
  truth = [field, seq0](Vec3 p) { return sh::irradiance_at(field->exact_sh({p}, 3, *seq0, 48, 1)[0], {0, 1, 0}); };
#endif
  auto seq = ilf::read_sequence(manifest);
  // Truth first, serially per point (the lab parallelises inside), then each grid.
  Image gt(kSlice, kSlice, 3);
  {
    double y = seq.volume.centre().y;
    for (int i = 0; i < kSlice * kSlice; ++i) {
      int px = i % kSlice, pz = i / kSlice;
      Vec3 p{seq.volume.min.x + seq.volume.size().x * (px + 0.5) / kSlice, y,
             seq.volume.min.z + seq.volume.size().z * (pz + 0.5) / kSlice};
      Vec3 e = truth(p);
      gt.set_rgb(px, pz, {std::max(0.0, e.x), std::max(0.0, e.y), std::max(0.0, e.z)});
    }
  }
  double scale = io::auto_exposure_scale(gt);
  io::ToneMapDesc td;
  td.auto_exposure = false;
  td.exposure_stops = std::log2(scale);
  nlohmann::json errs = nlohmann::json::object(), cv_errs = nlohmann::json::object();
  for (int n : {8, 16, 32}) {
    ilf::BuildDesc bd;
    bd.nx = bd.ny = bd.nz = n;
    bd.buckets.dir = (dir / "buckets").string();
    bd.buckets.octahedral = -1;
    bd.crossval.folds = 5;  // the error a user without the truth would see (docs/ilf.md, cross-validation)
    ilf::BuildReport rep;
    auto g = ilf::build_shgrid(seq, bd, {}, &rep);
    cv_errs[fmt::format("{}^3", n)] = rep.crossval->rel_error;
    iblcli::info(fmt::format("demo: ilf {}^3: cross-validated error {:.3f} ({}-fold over {} probes)", n,
                             rep.crossval->rel_error, rep.crossval->folds, rep.crossval->evaluated));
    {  // the error volume's slice through the same plane
      auto ev = ilf::error_volume(*rep.crossval, g.grid());
      ilf::write_shgrid((dir / fmt::format("error{}.shgrid", n)).string(), ev);
      std::string epng = (dir / fmt::format("cv_error_{}.png", n)).string();
      Image es = ilf::error_colours(ilf::error_slice(ev, 1, seq.volume.centre().y, kSlice * 4), 0.5),
            flipped(es.width(), es.height(), 3);
      for (int y = 0; y < es.height(); ++y)  // error_slice puts +z at the top; the irradiance slices above put −z there
        for (int x = 0; x < es.width(); ++x) flipped.set_rgb(x, es.height() - 1 - y, es.rgb(x, y));
      io::write_image(epng, io::resize(flipped, 256, 256));
      ctx.pictures.push_back({fmt::format("ILF {}^3 cross-validated error (black 0, red >= 0.5; overall {:.3f})", n,
                                          rep.crossval->rel_error),
                              epng});
    }
    ilf::write_shgrid((dir / fmt::format("grid{}.shgrid", n)).string(), g);
    Image s = slice(seq.volume, [&](Vec3 p) { return g.irradiance(p, {0, 1, 0}); });
    double num = 0, den = 0;
    for (size_t i = 0; i < s.size(); ++i) {
      num += std::pow(double(s.data()[i]) - gt.data()[i], 2);
      den += std::pow(double(gt.data()[i]), 2);
    }
    errs[fmt::format("{}^3", n)] = std::sqrt(num / den);
    std::string png = (dir / fmt::format("slice_{}.png", n)).string();
    io::write_image(png, io::resize(io::tonemap(s, td), 256, 256));
    ctx.pictures.push_back({fmt::format("ILF {}^3 grid (rel. err {:.3f})", n, std::sqrt(num / den)), png});
  }
  std::string png = (dir / "slice_truth.png").string();
  io::write_image(png, io::resize(io::tonemap(gt, td), 256, 256));
  ctx.pictures.push_back({fmt::format("ILF truth, {} irradiance y = mid", scene_name), png});
  ctx.summary["ilf"] = {{"scene", scene_name},
                        {"probes", seq.probes.size()},
                        {"slice_irradiance_rel_error", errs},
                        {"cv_sh_rel_error", cv_errs}};
}

iblcli::DemoStep step("ilf", 50, ilf_step);

}  // namespace
