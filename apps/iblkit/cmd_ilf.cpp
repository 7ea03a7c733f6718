// iblkit ilf build|adapt|densify|query|slice|info|synth: incident light fields — probe sequences resampled into SH
// grids (Löw et al. 2009, docs/ilf.md).
#include <unistd.h>

#include <chrono>
#include <filesystem>

#include <fmt/format.h>

#include "cli.h"
#include "iblkit/core/check.h"
#include "iblkit/core/error.h"
#include "iblkit/core/json_file.h"
#include "iblkit/ilf/adaptive.h"
#include "iblkit/ilf/analytic.h"
#include "iblkit/ilf/build.h"
#include "iblkit/ilf/distributed.h"
#include "iblkit/ilf/threejs_grid.h"
#include "iblkit/io/image_io.h"
#include "iblkit/io/tonemap.h"

namespace {

namespace fs = std::filesystem;
using namespace ibl;

std::vector<int> parse_grid(const std::string& s) {
  auto v = iblcli::parse_int_list(s, "--grid");
  if (v.size() == 1) v = {v[0], v[0], v[0]};
  if (v.size() != 3) fail(ErrorKind::Value, "--grid: expected N or NX,NY,NZ, got \"{}\"", s);
  for (int n : v)
    if (n < 2 || n > 1024) fail(ErrorKind::Value, "--grid: {} points per axis is outside [2, 1024]", n);
  return v;
}

ilf::Box parse_box(const std::string& s) {
  std::vector<double> v;
  size_t pos = 0;
  while (pos <= s.size()) {
    size_t e = s.find(',', pos);
    std::string t = s.substr(pos, e == std::string::npos ? std::string::npos : e - pos);
    try {
      v.push_back(std::stod(t));
    } catch (const std::exception&) {
      fail(ErrorKind::Value, "--volume: \"{}\" is not a number", t);
    }
    if (e == std::string::npos) break;
    pos = e + 1;
  }
  if (v.size() != 6) fail(ErrorKind::Value, "--volume: expected minx,miny,minz,maxx,maxy,maxz");
  ilf::Box b{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
  for (int a = 0; a < 3; ++a)
    if (!(b.max[a] > b.min[a])) fail(ErrorKind::Value, "--volume: max must exceed min on axis {}", "xyz"[a]);
  return b;
}

size_t parse_bytes(const std::string& s) {
  char* end = nullptr;
  double v = std::strtod(s.c_str(), &end);
  std::string unit = end ? std::string(end) : "";
  double mul = unit.empty() || unit == "B"   ? 1
               : unit == "K" || unit == "KB" ? 1e3 * 1.024
               : unit == "M" || unit == "MB" ? 1048576.0
               : unit == "G" || unit == "GB" ? 1073741824.0
                                             : -1;
  if (!(v > 0) || mul < 0) fail(ErrorKind::Value, "--memory: \"{}\" is not a size (e.g. 2G, 512M)", s);
  size_t bytes = size_t(v * mul);
  if (bytes < (size_t(64) << 20)) fail(ErrorKind::Value, "--memory: {} is below the 64M minimum", s);
  return bytes;
}

nlohmann::json report_json(const ilf::BuildReport& r) {
  return {{"probes_in", r.probes_in},
          {"probes_used", r.probes_used},
          {"skipped", r.skipped},
          {"subsampled_out", r.subsampled_out},
          {"buckets", r.buckets},
          {"blocks", r.blocks},
          {"octahedral", r.octahedral},
          {"samples", r.samples},
          {"fraction_uncovered", r.fraction_uncovered},
          {"buckets_reused", r.buckets_reused},
          {"seconds",
           {{"subsample", r.t_subsample},
            {"sort", r.t_sort},
            {"project", r.t_project},
            {"repair", r.t_repair},
            {"accumulate", r.t_accumulate},
            {"crossval", r.t_choose + r.t_crossval},
            {"total", r.t_total}}},
          {"gemm_gflop", r.gemm_flops * 1e-9},
          {"resolution", {r.nx, r.ny, r.nz}},
          {"kernel", r.kernel_cells},
          {"ball_radius", r.ball_radius},
          {"gemm_gflops_per_s", r.t_accumulate > 0 ? r.gemm_flops * 1e-9 / r.t_accumulate : 0.0},
          {"samples_per_s", r.t_total > 0 ? r.samples / r.t_total : 0.0}};
}

// The cross-validation and the automatic choice in --json (null entries where a region had no probe).
void add_crossval_json(nlohmann::json& j, const ilf::BuildReport& r) {
  if (r.choice) {
    nlohmann::json trials = nlohmann::json::array();
    for (const auto& t : r.choice->trials) {
      nlohmann::json t_j = {{"grid", t.n}, {"kernel", t.kernel}, {"cv_error", t.cv_error}};
      if (r.choice->focus) t_j["focus_error"] = t.focus_error;
      trials.push_back(t_j);
    }
    j["choice"] = {{"resolution", {r.choice->nx, r.choice->ny, r.choice->nz}},
                   {"kernel", r.choice->kernel},
                   {"buckets_used", r.choice->buckets_used},
                   {"seconds", r.choice->seconds},
                   {"trials", trials}};
    if (const auto& f = r.choice->focus)
      j["choice"]["focus"] = {{"centre", {f->centre.x, f->centre.y, f->centre.z}},
                              {"radius", f->radius},
                              {"sigma", r.choice->focus_sigma},
                              {"weight", r.choice->focus_weight},
                              {"error", r.choice->trials[r.choice->chosen].focus_error},
                              {"volume_kernel", r.choice->volume_kernel},
                              {"volume_grid", r.choice->volume_n}};
  }
  if (r.crossval) {
    const auto& c = *r.crossval;
    nlohmann::json regions = nlohmann::json::array();
    for (size_t i = 0; i < c.region_error.size(); ++i)
      regions.push_back(
          {{"index", {int(i) % c.regions, int(i) / c.regions % c.regions, int(i) / (c.regions * c.regions)}},
           {"probes", c.region_probes[i]},
           {"rel_error", std::isfinite(c.region_error[i]) ? nlohmann::json(c.region_error[i]) : nlohmann::json()}});
    j["crossval"] = {{"folds", c.folds},
                     {"evaluated", c.evaluated},
                     {"rel_error", c.rel_error},
                     {"median_probe_error", c.median_probe_error},
                     {"regions_per_axis", c.regions},
                     {"regions", regions}};
  }
}

// "--grid auto" or a resolution; "--kernel auto" or a width.
bool is_auto(const std::string& s) { return s == "auto"; }

nlohmann::json mpi_json(const ilf::DistributedReport& d) {
  return {{"ranks", d.ranks},
          {"chunk", d.chunk},
          {"blocks_per_rank", {d.blocks_min, d.blocks_max}},
          {"seconds",
           {{"subsample", d.t_subsample},
            {"read", d.t_read},
            {"exchange", d.t_exchange},
            {"project", d.t_project},
            {"repair", d.t_repair},
            {"accumulate", d.t_accumulate},
            {"reduce", d.t_reduce},
            {"crossval", d.t_crossval}}},
          {"bytes_sent", d.bytes_sent},
          {"bytes_received", d.bytes_received},
          {"bytes_reduced", d.bytes_reduced},
          {"bytes_crossval", d.bytes_crossval},
          {"peak_rss_bytes", d.peak_rss_bytes}};
}

// Inverse of parse_bytes for the --memory default: whole gibibytes or mebibytes as "2G", "512M".
std::string format_bytes(size_t bytes) {
  if (bytes % (size_t(1) << 30) == 0) return fmt::format("{}G", bytes >> 30);
  if (bytes % (size_t(1) << 20) == 0) return fmt::format("{}M", bytes >> 20);
  return fmt::format("{}B", bytes);
}

// --directions of BucketDesc::octahedral: −1 auto, 0 pixel, n an n×n octahedral grid.
std::string directions_name(int octahedral) {
  return octahedral < 0 ? "auto" : octahedral == 0 ? "pixel" : std::to_string(octahedral);
}

// A CLI11 check: empty when `v` is a number > 0 (or no number at all: the conversion then says so).
std::string positive_number(const std::string& v) {
  char* end = nullptr;
  double d = std::strtod(v.c_str(), &end);
  if (end == v.c_str() || *end != '\0') return "";
  return d > 0 ? "" : "must be > 0, got " + v;
}

// Defaults come from BuildDesc (and the descs it holds); the strings are their parsed forms.
struct BuildOptions {
  ilf::BuildDesc bd;
  std::string seq, out, volume, buckets, vdb, error_grid, focus, kernel = "auto";
  std::string grid =
      bd.nx == bd.ny && bd.ny == bd.nz ? std::to_string(bd.nx) : fmt::format("{},{},{}", bd.nx, bd.ny, bd.nz);
  std::string repair = ilf::repair_name(bd.project.repair), memory = format_bytes(bd.buckets.memory_bytes);
  std::string directions = directions_name(bd.buckets.octahedral);
  double subsample = -1, subsample_dist = ilf::SubsampleDesc{}.max_distance;  // off unless given
  CLI::Option* subsample_opt = nullptr;
  bool no_reuse = !bd.buckets.reuse, drop_buckets = false;
  bool no_parallax = !bd.ball_parallax;
  bool mpi = false;
  double mpi_timeout = ilf::MpiJobDesc{}.timeout_s;
};

// The build and its report; job: this rank of an MPI job (rank 0 writes and prints), or none.
void run_build(const BuildOptions& opts, const ilf::SequenceReadDesc& rd, const ilf::BuildDesc& bd, ilf::MpiJob* job) {
  const BuildOptions* o = &opts;
  ilf::SequenceReport srep;
  ilf::Sequence seq;
  ilf::BuildReport rep;
  ilf::DistributedReport drep;
  ilf::SHGrid g;
  double t_write = 0;
  if (job) {
    job->agree([&] { seq = ilf::read_sequence(o->seq, rd, &srep); });
    // Rank 0 draws the one bar of the job; under mpirun its stderr is a pipe and its stdout the terminal.
    auto bar =
        job->rank() == 0 ? iblcli::progress_bar(isatty(STDERR_FILENO) || isatty(STDOUT_FILENO)) : ibl::ProgressFn{};
    g = job->build(seq, bd, bar, &rep, &drep);
    iblcli::progress_done();
    if (job->rank() != 0) return;
  } else {
    seq = ilf::read_sequence(o->seq, rd, &srep);
    g = ilf::build_shgrid(seq, bd, iblcli::progress_bar(), &rep);
    iblcli::progress_done();
  }
  {
    auto tw = std::chrono::steady_clock::now();
    ilf::write_shgrid(o->out, g);
    if (!o->vdb.empty()) ilf::write_vdb(o->vdb, g);
    if (!o->error_grid.empty()) ilf::write_shgrid(o->error_grid, ilf::error_volume(*rep.crossval, g.grid()));
    t_write = std::chrono::duration<double>(std::chrono::steady_clock::now() - tw).count();
  }
  if (o->drop_buckets) ilf::remove_bucket_cache(bd.buckets.dir);
  rep.skipped += srep.skipped;
  for (auto& r : srep.reasons) rep.skip_reasons.insert(rep.skip_reasons.begin(), r);
  for (auto& r : rep.skip_reasons) iblcli::info("skipped: " + r);
  auto j = report_json(rep);
  j["out"] = o->out;
  j["seconds"]["write"] = t_write;
  if (job) j["mpi"] = mpi_json(drep);
  add_crossval_json(j, rep);
  if (!o->error_grid.empty()) j["error_grid"] = o->error_grid;
  iblcli::emit(j, [&] {
    fmt::print("wrote {} ({}x{}x{}, {} coefficients)\n", o->out, g.grid().nx, g.grid().ny, g.grid().nz,
               bd.bands * bd.bands);
    fmt::print("kernel    {:g} grid cells{}{}\n", rep.choice ? rep.kernel_cells : bd.project.kernel_cells,
               rep.choice ? fmt::format(" (chosen of {} cross-validated trials on {} buckets in {:.1f}s{})",
                                        rep.choice->trials.size(), rep.choice->buckets_used, rep.choice->seconds,
                                        bd.auto_grid ? ", with the grid" : "")
                          : "",
               rep.ball_radius > 0 ? fmt::format("; rays start on the ball (radius {:g} m)", rep.ball_radius) : "");
    if (rep.choice && rep.choice->focus) {
      const auto& ch = *rep.choice;
      const auto& f = *ch.focus;
      fmt::print(
          "focus     {:g},{:g},{:g} (σ {:.3g} m, {:.1f} probes' weight): cv error there {:.4f}; the whole "
          "volume's choice would be {:g} cells{}\n",
          f.centre.x, f.centre.y, f.centre.z, ch.focus_sigma, ch.focus_weight, ch.trials[ch.chosen].focus_error,
          ch.volume_kernel, bd.auto_grid ? fmt::format(" on a {}-point grid", ch.volume_n) : "");
    }
    if (rep.crossval) {
      const auto& c = *rep.crossval;
      fmt::print("cv error  {:.4f} relative ({}-fold, {} probes; median probe {:.4f})\n", c.rel_error, c.folds,
                 c.evaluated, c.median_probe_error);
      std::string regs;
      for (size_t i = 0; i < c.region_error.size(); ++i)
        regs += std::isfinite(c.region_error[i]) ? fmt::format(" {:.3f}", c.region_error[i]) : " -";
      fmt::print("  regions {}³ (x fastest, then y, z):{}\n", c.regions, regs);
    }
    if (!o->error_grid.empty()) fmt::print("wrote {} (cross-validated error volume)\n", o->error_grid);
    fmt::print("probes    {} used of {} in the manifest{}{}\n", rep.probes_used, rep.probes_in + srep.skipped,
               rep.skipped ? fmt::format(", {} skipped as bad", rep.skipped) : "",
               rep.subsampled_out ? fmt::format(", {} dropped by --subsample", rep.subsampled_out) : "");
    fmt::print("buckets   {} ({}), {} blocks{}\n", rep.buckets,
               rep.octahedral ? fmt::format("{0}x{0} octahedral", rep.octahedral) : "one per pixel", rep.blocks,
               rep.buckets_reused ? ", reused" : "");
    fmt::print("samples   {} ({:.3g}/s), {:.2f}% of grid point × bucket pairs repaired\n", rep.samples,
               rep.samples / std::max(rep.t_total, 1e-9), 100 * rep.fraction_uncovered);
    fmt::print("time      sort {:.1f}s, project+repair {:.1f}s, SH products {:.1f}s ({:.1f} GFLOP/s), total {:.1f}s\n",
               rep.t_sort, rep.t_project, rep.t_accumulate, rep.gemm_flops * 1e-9 / std::max(rep.t_accumulate, 1e-9),
               rep.t_total);
    if (job)
      fmt::print(
          "ranks     {}: read {:.1f}s, exchange {:.1f}s ({:.3g} MB sent by the busiest rank), cross-validation "
          "{:.1f}s, "
          "project {:.1f}s (repair {:.1f}s), SH {:.1f}s, reduce {:.1f}s, write {:.1f}s; peak memory {:.0f} MB per "
          "rank\n",
          drep.ranks, drep.t_read, drep.t_exchange, drep.bytes_sent * 1e-6, drep.t_crossval, drep.t_project,
          drep.t_repair, drep.t_accumulate, drep.t_reduce, t_write, drep.peak_rss_bytes * 1e-6);
  });
}

void setup_build(CLI::App& app) {
  using Opts = BuildOptions;
  auto* o = iblcli::app_owned<Opts>();
  auto& bd0 = o->bd;
  app.add_option("sequence", o->seq, "iblkit.sequence/1 manifest")->required();
  app.add_option("-o,--out", o->out, "output .shgrid")->required();
  app.add_option("--grid", o->grid,
                 "grid points: N, NX,NY,NZ, or auto (cross-validated choice among 8…64 within --memory)")
      ->capture_default_str();
  app.add_option("--bands", bd0.bands, "SH bands (5 = 25 coefficients)")
      ->capture_default_str()
      ->check(CLI::Range(ilf::kMinBuildBands, ilf::kMaxBuildBands));
  app.add_option("--volume", o->volume, "grid volume minx,miny,minz,maxx,maxy,maxz (default: the sequence's)");
  app.add_option("--kernel", o->kernel,
                 "Gaussian kernel support diameter in grid cells, or auto (cross-validated choice among 1.5…4)")
      ->capture_default_str()
      ->check([](const std::string& v) {
        if (v == "auto") return std::string();
        char* end = nullptr;
        std::strtod(v.c_str(), &end);
        if (end == v.c_str() || *end != '\0') return "expected auto or a number of grid cells, got " + v;
        return positive_number(v);
      });
  bd0.crossval.folds = 5;  // the CLI cross-validates by default
  app.add_option("--cv-folds", bd0.crossval.folds,
                 "k-fold cross-validation of the grid against its own probes (0: off)")
      ->capture_default_str()
      ->check([](const std::string& v) {
        char* end = nullptr;
        long n = std::strtol(v.c_str(), &end, 10);
        return end != v.c_str() && *end == '\0' && (n == 0 || (n >= 2 && n <= 255))
                   ? std::string()
                   : "expected 0 or 2 to 255, got " + v;
      });
  app.add_option("--focus", o->focus,
                 "x,y,z[,radius]: choose the kernel (and an auto grid) for this neighbourhood, where the object "
                 "will be lit: the cross-validated error of the probes around it, not the whole volume's");
  app.add_option("--error-grid", o->error_grid,
                 "write the cross-validated error volume here (a one-band .shgrid; ilf slice shows it)");
  app.add_option("--repair", o->repair, "filling of grid points no ray reached: mip (the paper's), pullpush, none")
      ->capture_default_str();
  app.add_option("--memory", o->memory, "peak memory budget (e.g. 2G, 512M)")->capture_default_str();
  app.add_option("--buckets", o->buckets, "folder for the direction buckets (default: OUT.buckets; reused by re-runs)");
  app.add_option("--directions", o->directions,
                 "direction buckets: auto, pixel (one per probe pixel, the paper's) or N (N×N octahedral cells)")
      ->capture_default_str();
  o->subsample_opt = app.add_option("--subsample", o->subsample,
                                    "drop probes whose difference energy to both neighbours is below this (e.g. 0.05)");
  app.add_option("--subsample-distance", o->subsample_dist, "… and whose neighbours lie within this many metres")
      ->capture_default_str();
  app.add_option("--vdb", o->vdb, "also write the grid as OpenVDB (one Vec3f grid per coefficient)");
  iblcli::outputs(app, {"--error-grid", "--vdb", "--buckets"});  // besides --out (cli.h)
  app.add_flag("--skip-bad", bd0.buckets.skip_bad,
               "skip bad probes (missing/unreadable frames, wrong size, NaN, outside the volume, duplicates) and "
               "report how many");
  app.add_flag("--sanitize", bd0.buckets.sanitize, "replace NaN/Inf/negative pixels by 0 instead of failing");
  app.add_flag("--no-reuse", o->no_reuse, "rebuild the direction buckets even when an earlier run's match");
  app.add_flag("--drop-buckets", o->drop_buckets,
               "remove the direction buckets once the grid is written (a re-run sorts again)");
  app.add_flag("--no-parallax", o->no_parallax,
               "ignore the manifest's ball_radius: every ray through the probe position (single viewpoint)");
  app.add_flag("--mpi", o->mpi,
               "build as a rank of an MPI job (the default under mpirun): mpirun -np N iblkit ilf build …");
  app.add_option("--mpi-timeout", o->mpi_timeout,
                 "MPI: seconds the ranks wait for each other at the start before the job ends naming the missing one")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 86400.0));
  app.footer(
      "Examples:\n  iblkit ilf build cap/sequence.json --grid 8 --bands 5 --out room8.shgrid\n"
      "  iblkit ilf build cap/sequence.json --grid 8 --focus 0.1,0.3,0.1,0.15 --out object8.shgrid   # the kernel "
      "for an object there\n"
      "  mpirun -np 4 iblkit ilf build captures/sequence.json --grid 32 --out room.shgrid   (docs/ilf.md, \"On a "
      "cluster\")");
  app.callback([o, &app] {
    bool grid_auto = is_auto(o->grid);
    auto grid = grid_auto ? std::vector<int>{16, 16, 16} : parse_grid(o->grid);
    if (!o->vdb.empty() && !ilf::have_vdb()) ilf::write_vdb(o->vdb, ilf::SHGrid());  // fails now, not after the build
    ilf::BuildDesc bd = o->bd;
    bd.nx = grid[0];
    bd.ny = grid[1];
    bd.nz = grid[2];
    bd.auto_grid = grid_auto;
    bd.auto_kernel = is_auto(o->kernel);
    if (!bd.auto_kernel) bd.project.kernel_cells = std::stod(o->kernel);
    if (!o->error_grid.empty() && bd.crossval.folds < 2)
      fail(ErrorKind::Value, "--error-grid needs the cross-validation (--cv-folds ≥ 2)");
    if (!o->volume.empty()) bd.volume = parse_box(o->volume);
    if (!o->focus.empty()) {
      auto v = iblcli::parse_double_list(o->focus, "--focus");
      if (v.size() != 3 && v.size() != 4)
        fail(ErrorKind::Value, "--focus: expected x,y,z or x,y,z,radius, got {}", o->focus);
      bd.focus = ilf::Focus{{v[0], v[1], v[2]}, v.size() == 4 ? v[3] : 0.0};
      if (!bd.auto_kernel && !bd.auto_grid)
        fail(ErrorKind::Value,
             "--focus chooses the kernel for a neighbourhood: it needs --kernel auto (the default) "
             "or --grid auto, not --kernel {}",
             o->kernel);
    }
    bd.project.repair = ilf::parse_repair(o->repair);
    bd.buckets.memory_bytes = parse_bytes(o->memory);
    bd.buckets.dir = o->buckets.empty() ? o->out + ".buckets" : o->buckets;
    bd.buckets.reuse = !o->no_reuse;
    bd.ball_parallax = !o->no_parallax;
    if (o->directions == "auto")
      bd.buckets.octahedral = -1;
    else if (o->directions == "pixel")
      bd.buckets.octahedral = 0;
    else {
      auto v = iblcli::parse_int_list(o->directions, "--directions");
      if (v.size() != 1 || v[0] < 2 || v[0] > 1024)
        fail(ErrorKind::Value, "--directions: expected auto, pixel or N in [2, 1024]");
      bd.buckets.octahedral = v[0];
    }
    if (o->subsample_opt->count() > 0) bd.subsample = ilf::SubsampleDesc{o->subsample, o->subsample_dist};
    ilf::SequenceReadDesc rd;
    rd.skip_bad = bd.buckets.skip_bad;
    if (o->mpi || ilf::launched_by_mpi()) {
      // The ranks first agree on the command line (every option's value) and then on the job itself.
      ilf::MpiJobDesc job{iblcli::describe_options(app), o->mpi_timeout};
      ilf::run_mpi_job(job, [&](ilf::MpiJob& job) { run_build(*o, rd, bd, &job); });
    } else {
      run_build(*o, rd, bd, nullptr);
    }
  });
}

// `ilf query` on a dense or an adaptive grid (the same lookups).
struct QueryOpts {
  std::string grid, at, normal, dir, points;
  double exponent = 4;
};

// --points: the coefficients at every point of a JSON array [[x, y, z], …].
template <typename Grid>
void query_points(const Grid& g, const std::string& path) {
  const nlohmann::json pts = read_json_file(path);
  if (!pts.is_array()) fail(ErrorKind::Format, "{}: expected a JSON array of points [x, y, z]", path);
  nlohmann::json rows = nlohmann::json::array();
  for (size_t i = 0; i < pts.size(); ++i) {
    const auto& q = pts[i];
    if (!q.is_array() || q.size() != 3 || !q[0].is_number() || !q[1].is_number() || !q[2].is_number())
      fail(ErrorKind::Format, "{}: point {} is not [x, y, z]", path, i);
    Vec3 p{q[0].get<double>(), q[1].get<double>(), q[2].get<double>()};
    require_point(fmt::format("{}: point {}", path, i), p);
    nlohmann::json coeffs = nlohmann::json::array();
    for (auto& v : g.coeffs_at(p).c) coeffs.push_back({v.x, v.y, v.z});
    rows.push_back(coeffs);
  }
  iblcli::emit({{"points", pts.size()}, {"coefficients", rows}},
               [&] { fmt::print("{} points: the coefficients need --json\n", pts.size()); });
}

template <typename Grid>
void query(const Grid& g, const QueryOpts& opts) {
  const QueryOpts* o = &opts;
  if (!o->points.empty()) return query_points(g, o->points);
  if (o->at.empty()) fail(ErrorKind::Value, "ilf query: give --at x,y,z or --points FILE");
  Vec3 p = iblcli::parse_vec3(o->at, "--at"),
       n = o->normal.empty() ? Vec3{0, 1, 0} : iblcli::parse_vec3(o->normal, "--normal");
  require_point("--at", p);
  if (!g.grid().volume.contains(p))
    iblcli::info("note: the point lies outside the grid volume; values are clamped to its boundary");
  auto c = g.coeffs_at(p);
  Vec3 e = g.irradiance(p, n);
  nlohmann::json coeffs = nlohmann::json::array();
  for (auto& v : c.c) coeffs.push_back({v.x, v.y, v.z});
  nlohmann::json j = {
      {"at", {p.x, p.y, p.z}}, {"normal", {n.x, n.y, n.z}}, {"irradiance", {e.x, e.y, e.z}}, {"coefficients", coeffs}};
  if constexpr (std::is_same_v<Grid, ilf::AdaptiveGrid>) j["level"] = g.level_at(p);
  Vec3 L, G;
  if (!o->dir.empty()) {
    Vec3 d = iblcli::parse_vec3(o->dir, "--dir");
    L = g.radiance(p, d);
    G = g.glossy(p, d, o->exponent);
    j["radiance"] = {L.x, L.y, L.z};
    j["glossy"] = {G.x, G.y, G.z};
  }
  iblcli::emit(j, [&] {
    fmt::print("irradiance  {:.6g} {:.6g} {:.6g}  (normal {:.3g},{:.3g},{:.3g})\n", e.x, e.y, e.z, n.x, n.y, n.z);
    if (!o->dir.empty()) {
      fmt::print("radiance    {:.6g} {:.6g} {:.6g}\n", L.x, L.y, L.z);
      fmt::print("glossy      {:.6g} {:.6g} {:.6g}  (Phong exponent {})\n", G.x, G.y, G.z, o->exponent);
    }
    fmt::print("c00         {:.6g} {:.6g} {:.6g}\n", c.c[0].x, c.c[0].y, c.c[0].z);
    if constexpr (std::is_same_v<Grid, ilf::AdaptiveGrid>)
      fmt::print("level       {} (of {}; 0 = the fine grid's resolution)\n", g.level_at(p), g.levels() - 1);
  });
}

void setup_query(CLI::App& app) {
  auto* o = iblcli::app_owned<QueryOpts>();
  app.add_option("grid", o->grid, ".shgrid or .shtree file")->required();
  app.add_option("--at", o->at, "point x,y,z");
  app.add_option("--points", o->points,
                 "instead of --at: a JSON array of points [[x, y, z], …]; --json prints the coefficients at each");
  app.add_option("--normal", o->normal, "irradiance for this normal x,y,z (default +Y)");
  app.add_option("--dir", o->dir, "also radiance towards, and Phong-glossy response around, this direction");
  app.add_option("--exponent", o->exponent, "Phong exponent for --dir")->capture_default_str();
  app.footer(
      "Examples:\n  iblkit ilf query room.shgrid --at 0.1,0.5,0 --normal 0,1,0\n  iblkit ilf query room.shtree --at "
      "0.1,0.5,0 --normal 0,1,0");
  app.callback([o] {
    if (ilf::is_adaptive_file(o->grid))
      query(ilf::read_adaptive(o->grid), *o);
    else
      query(ilf::read_shgrid(o->grid), *o);
  });
}

// Irradiance on an axis-aligned plane through the volume, normal along the plane's axis.
// A template: the grid is an ilf::SHGrid or an ilf::AdaptiveGrid; with `levels`, each pixel is the level
// of the adaptive grid that answers there instead (1 at level 0, the fine grid, down to 0 at the top).
template <typename Grid>
Image irradiance_slice(const Grid& g, int axis, double value, int size, double normal_sign, bool levels = false) {
  const auto& v = g.grid().volume;
  int a1 = axis == 0 ? 2 : 0, a2 = axis == 1 ? 2 : 1;  // image x, y axes
  Vec3 ext = v.size();
  int w = size, h = int(std::clamp(std::lround(size * ext[a2] / ext[a1]), 1L, 16384L));
  Image img(w, h, 3);
  Vec3 n{0, 0, 0};
  n[axis] = normal_sign;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Vec3 p;
      p[axis] = value;
      p[a1] = v.min[a1] + ext[a1] * (x + 0.5) / w;
      p[a2] = v.max[a2] - ext[a2] * (y + 0.5) / h;
      if constexpr (std::is_same_v<Grid, ilf::AdaptiveGrid>)
        if (levels) {
          double l = 1.0 - double(g.level_at(p)) / std::max(1, g.levels() - 1);
          img.set_rgb(x, y, {l, l, l});
          continue;
        }
      Vec3 e = g.irradiance(p, n);
      img.set_rgb(x, y, {std::max(0.0, e.x), std::max(0.0, e.y), std::max(0.0, e.z)});
    }
  return img;
}

void setup_slice(CLI::App& app) {
  struct Opts {
    std::string grid, plane, out;
    int size = 256;
    bool down = false, levels = false;
    double exposure = 0, max_error = 0.5;
  };
  auto* o = iblcli::app_owned<Opts>();
  app.add_option("grid", o->grid, ".shgrid or .shtree file")->required();
  app.add_option("--plane", o->plane, "axis-aligned plane, e.g. y=0.3")->required();
  app.add_option("-o,--out", o->out, "output image (.png tone mapped, .exr linear W/m²)")->required();
  app.add_option("--size", o->size, "image width in pixels")->capture_default_str()->check(CLI::Range(8, 8192));
  app.add_flag("--down", o->down, "normal along the negative axis (default: positive)");
  app.add_flag(
      "--levels", o->levels,
      "adaptive grids (.shtree): draw the level that answers at each pixel (white: the fine grid's, black: the top)");
  app.add_option("--max-error", o->max_error, "error volumes (ilf build --error-grid): the relative error shown red")
      ->capture_default_str()
      ->check(positive_number);
  app.footer(
      "An error volume (ilf build --error-grid) is drawn as its relative error in false colour (.png: black 0,\n"
      "blue, green, yellow, red at --max-error; grey: under one probe's weight near, no figure) or as its three "
      "channels (.exr: relative, absolute, weight).\n"
      "Examples:\n  iblkit ilf slice room.shgrid --plane y=0.3 --out slice.png\n"
      "  iblkit ilf slice room.shtree --plane y=0.3 --levels --out levels.png");
  app.callback([o] {
    const bool adaptive = ilf::is_adaptive_file(o->grid);
    if (o->levels && !adaptive) fail(ErrorKind::Value, "--levels: {} is not an adaptive grid (.shtree)", o->grid);
    auto g = adaptive ? ilf::SHGrid() : ilf::read_shgrid(o->grid, true);
    auto eq = o->plane.find('=');
    std::string ax = eq == std::string::npos ? "" : o->plane.substr(0, eq);
    int axis = ax == "x" ? 0 : ax == "y" ? 1 : ax == "z" ? 2 : -1;
    if (axis < 0) fail(ErrorKind::Value, "--plane: expected x=V, y=V or z=V, got \"{}\"", o->plane);
    double val;
    try {
      val = std::stod(o->plane.substr(eq + 1));
    } catch (const std::exception&) {
      fail(ErrorKind::Value, "--plane: \"{}\" is not a number", o->plane.substr(eq + 1));
    }
    if (!std::isfinite(val) || std::abs(val) > kMaxCoordinate)
      fail(ErrorKind::Value, "--plane: {} must be a finite coordinate within ±{:g} m", o->plane, kMaxCoordinate);
    if (o->size < 1 || o->size > 16384) fail(ErrorKind::Value, "--size {}: expected 1 to 16384 pixels", o->size);
    std::string ext = fs::path(o->out).extension().string();
    if (g.content() == "cv-error") {
      Image e = ilf::error_slice(g, axis, val, o->size);
      if (ext == ".png" || ext == ".jpg")
        io::write_image(o->out, io::tonemap(ilf::error_colours(e, o->max_error), [] {
                          io::ToneMapDesc td;
                          td.auto_exposure = false;
                          td.curve = io::ToneCurve::Clamp;
                          return td;
                        }()));
      else
        io::write_image(o->out, e);
      double mx = 0, sum = 0;
      for (int y = 0; y < e.height(); ++y)
        for (int x = 0; x < e.width(); ++x) {
          mx = std::max<double>(mx, e.rgb(x, y).x);
          sum += e.rgb(x, y).x;
        }
      double mean = sum / (double(e.width()) * e.height());
      iblcli::emit({{"out", o->out},
                    {"width", e.width()},
                    {"height", e.height()},
                    {"content", "cv-error"},
                    {"max_rel_error", mx},
                    {"mean_rel_error", mean}},
                   [&] {
                     fmt::print("wrote {} ({}x{}), cross-validated relative error: mean {:.3f}, max {:.3f}\n", o->out,
                                e.width(), e.height(), mean, mx);
                   });
      return;
    }
    if (!g.content().empty())
      fail(ErrorKind::Value, "{}: content \"{}\" is neither radiance SH nor cv-error", o->grid, g.content());
    Image img = adaptive
                    ? irradiance_slice(ilf::read_adaptive(o->grid), axis, val, o->size, o->down ? -1 : 1, o->levels)
                    : irradiance_slice(g, axis, val, o->size, o->down ? -1 : 1);
    if (o->levels) {
      io::ToneMapDesc td;
      td.auto_exposure = false;
      td.curve = io::ToneCurve::Clamp;
      if (ext == ".png" || ext == ".jpg")
        io::write_image(o->out, io::tonemap(img, td));
      else
        io::write_image(o->out, img);
      iblcli::emit({{"out", o->out}, {"width", img.width()}, {"height", img.height()}, {"content", "levels"}}, [&] {
        fmt::print("wrote {} ({}x{}), the answering level (white: level 0)\n", o->out, img.width(), img.height());
      });
      return;
    }
    if (ext == ".png" || ext == ".jpg")
      io::write_image(o->out, io::tonemap(img));
    else
      io::write_image(o->out, img);
    double mx = 0;
    for (size_t i = 0; i < img.size(); ++i) mx = std::max<double>(mx, img.data()[i]);
    iblcli::emit({{"out", o->out}, {"width", img.width()}, {"height", img.height()}, {"max_irradiance", mx}}, [&] {
      fmt::print("wrote {} ({}x{}), max irradiance {:.4g} W/m²\n", o->out, img.width(), img.height(), mx);
    });
  });
}

// The levels of an adaptive grid, its bytes against the dense fine grid's, and what it was built with.
nlohmann::json levels_json(const ilf::AdaptiveGrid& t) {
  nlohmann::json levels = nlohmann::json::array();
  for (int l = 0; l < t.levels(); ++l) {
    const auto& L = t.level(l);
    levels.push_back({{"level", l},
                      {"step", L.step},
                      {"points", {L.n[0], L.n[1], L.n[2]}},
                      {"bricks", L.bricks.size()},
                      {"brick_slots", L.map.size()}});
  }
  return levels;
}

// Bytes of the .shgrid of the tree's fine grid (header and values).
double dense_file_bytes(const ilf::AdaptiveGrid& t) { return double(t.grid().count()) * t.coeff_count() * 3 * 4 + 256; }

void print_levels(const ilf::AdaptiveGrid& t) {
  for (int l = 0; l < t.levels(); ++l) {
    const auto& L = t.level(l);
    fmt::print("  level {:<2} step {:<4} {}x{}x{} points, {} of {} bricks\n", l, L.step, L.n[0], L.n[1], L.n[2],
               L.bricks.size(), L.map.size());
  }
}

void adaptive_info(const std::string& path, const ilf::AdaptiveGrid& t) {
  const auto& gd = t.grid();
  const double bytes = double(t.file_bytes()), dense = dense_file_bytes(t);
  nlohmann::json j = {{"file", path},
                      {"adaptive", true},
                      {"bands", t.bands()},
                      {"coefficients", t.coeff_count()},
                      {"resolution", {gd.nx, gd.ny, gd.nz}},
                      {"min", {gd.volume.min.x, gd.volume.min.y, gd.volume.min.z}},
                      {"max", {gd.volume.max.x, gd.volume.max.y, gd.volume.max.z}},
                      {"brick", t.brick()},
                      {"tolerance", t.tolerance()},
                      {"rms", t.rms()},
                      {"stored_points", t.stored_points()},
                      {"bytes", bytes},
                      {"dense_bytes", dense},
                      {"levels", levels_json(t)}};
  iblcli::emit(j, [&] {
    fmt::print("file        {}\n", path);
    fmt::print("grid        adaptive, fine grid {}x{}x{}, {} bands ({} coefficients), bricks of {}³ cells\n", gd.nx,
               gd.ny, gd.nz, t.bands(), t.coeff_count(), t.brick());
    fmt::print("volume      ({:.4g}, {:.4g}, {:.4g}) .. ({:.4g}, {:.4g}, {:.4g})\n", gd.volume.min.x, gd.volume.min.y,
               gd.volume.min.z, gd.volume.max.x, gd.volume.max.y, gd.volume.max.z);
    fmt::print("stored      {} points, {:.2f} MB ({:.1f}% of the dense fine grid's {:.2f} MB)\n", t.stored_points(),
               bytes / 1048576.0, 100 * bytes / dense, dense / 1048576.0);
    fmt::print("tolerance   {:g} × RMS {:.6g} (per fine point, L2 of the coefficients)\n", t.tolerance(), t.rms());
    print_levels(t);
  });
}

void setup_info(CLI::App& app) {
  auto* path = iblcli::app_owned<std::string>();
  app.add_option("grid", *path, ".shgrid or .shtree file")->required();
  app.footer("Examples:\n  iblkit ilf info room.shgrid\n  iblkit ilf info room.shtree");
  app.callback([path] {
    if (ilf::is_adaptive_file(*path)) return adaptive_info(*path, ilf::read_adaptive(*path));
    auto g = ilf::read_shgrid(*path, true);
    const auto& gd = g.grid();
    double lo = 1e300, hi = -1e300;
    int K = g.coeff_count();
    for (int64_t i = 0; i < gd.count(); ++i)
      for (int c = 0; c < 3; ++c) {
        double v = g.data()[size_t(i) * K * 3 + c];
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    nlohmann::json j = {{"file", *path},
                        {"bands", g.bands()},
                        {"coefficients", K},
                        {"resolution", {gd.nx, gd.ny, gd.nz}},
                        {"min", {gd.volume.min.x, gd.volume.min.y, gd.volume.min.z}},
                        {"max", {gd.volume.max.x, gd.volume.max.y, gd.volume.max.z}},
                        {"bytes", g.data().size() * 4},
                        {"c00_range", {lo, hi}}};
    if (!g.content().empty()) j["content"] = g.content();
    iblcli::emit(j, [&] {
      fmt::print("file        {}\n", *path);
      fmt::print("grid        {}x{}x{}, {} bands ({} coefficients), {:.1f} MB\n", gd.nx, gd.ny, gd.nz, g.bands(), K,
                 g.data().size() * 4 / 1048576.0);
      fmt::print("volume      ({:.4g}, {:.4g}, {:.4g}) .. ({:.4g}, {:.4g}, {:.4g})\n", gd.volume.min.x, gd.volume.min.y,
                 gd.volume.min.z, gd.volume.max.x, gd.volume.max.y, gd.volume.max.z);
      fmt::print("c00 range   {:.6g} .. {:.6g}\n", lo, hi);
      if (!g.content().empty())
        fmt::print("content     {} (channel 1: relative error, 2: absolute, 3: probe weight)\n", g.content());
    });
  });
}

void setup_adapt(CLI::App& app) {
  struct Opts {
    std::string grid, out;
    ilf::AdaptDesc d;
  };
  auto* o = iblcli::app_owned<Opts>();
  app.add_option("grid", o->grid, "dense .shgrid (the fine grid)")->required();
  app.add_option("-o,--out", o->out, "output .shtree")->required();
  app.add_option("--tolerance", o->d.tolerance,
                 "largest error kept at any fine point: L2 of its coefficients' difference, relative to the grid's RMS")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
  app.add_option("--brick", o->d.brick, "cells per brick axis")
      ->capture_default_str()
      ->check(CLI::Range(ilf::kMinBrick, ilf::kMaxBrick));
  app.footer(
      "Keeps the fine grid's points only where a coarser level (each halves the resolution) misses them by more\n"
      "than --tolerance; query, slice, info read the result, densify writes a dense grid back (docs/ilf.md).\n"
      "Example:\n  iblkit ilf adapt room.shgrid --tolerance 0.02 --out room.shtree");
  app.callback([o] {
    auto t0 = std::chrono::steady_clock::now();
    auto fine = ilf::read_shgrid(o->grid);
    auto t = ilf::make_adaptive(fine, o->d);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ilf::write_adaptive(o->out, t);
    // Measured, not assumed: the tree's difference to the fine grid at every fine point.
    auto back = t.to_dense();
    const int KC = fine.coeff_count() * 3;
    double worst = 0, num = 0, den = 0;
    for (int64_t i = 0; i < fine.grid().count(); ++i) {
      double e = 0;
      for (int q = 0; q < KC; ++q) {
        double a = back.data()[size_t(i) * KC + q], b = fine.data()[size_t(i) * KC + q];
        e += (a - b) * (a - b);
        den += b * b;
      }
      num += e;
      worst = std::max(worst, std::sqrt(e));
    }
    const double rel_l2 = den > 0 ? std::sqrt(num / den) : 0.0, bytes = double(t.file_bytes());
    const double dense = double(std::filesystem::file_size(o->grid));
    nlohmann::json j = {{"grid", o->grid},
                        {"out", o->out},
                        {"tolerance", t.tolerance()},
                        {"brick", t.brick()},
                        {"rms", t.rms()},
                        {"stored_points", t.stored_points()},
                        {"fine_points", fine.grid().count()},
                        {"bytes", bytes},
                        {"dense_bytes", dense},
                        {"ratio", bytes / dense},
                        {"max_point_error", t.rms() > 0 ? worst / t.rms() : 0.0},
                        {"rel_l2_to_fine", rel_l2},
                        {"seconds", seconds},
                        {"levels", levels_json(t)}};
    iblcli::emit(j, [&] {
      fmt::print("wrote {} ({:.2f} MB, {:.1f}% of {}'s {:.2f} MB) in {:.2f}s\n", o->out, bytes / 1048576.0,
                 100 * bytes / dense, o->grid, dense / 1048576.0, seconds);
      fmt::print("to the fine grid: largest point error {:.4g} × RMS (tolerance {:g}), relative L2 {:.4g}\n",
                 t.rms() > 0 ? worst / t.rms() : 0.0, t.tolerance(), rel_l2);
      print_levels(t);
    });
  });
}

void setup_densify(CLI::App& app) {
  struct Opts {
    std::string tree, out, grid;
  };
  auto* o = iblcli::app_owned<Opts>();
  app.add_option("tree", o->tree, "adaptive grid (.shtree)")->required();
  app.add_option("-o,--out", o->out, "output .shgrid")->required();
  app.add_option("--grid", o->grid, "points N or NX,NY,NZ (default: the fine grid's)");
  app.footer(
      "The dense grid the renderers, export-threejs and the viewer load (they also read .shtree this way).\n"
      "Example:\n  iblkit ilf densify room.shtree --out room-dense.shgrid");
  app.callback([o] {
    auto t = ilf::read_adaptive(o->tree);
    auto n = o->grid.empty() ? std::vector<int>{t.grid().nx, t.grid().ny, t.grid().nz} : parse_grid(o->grid);
    require_allocation(fmt::format("densify: {}x{}x{} points of {} bands", n[0], n[1], n[2], t.bands()),
                       double(n[0]) * n[1] * n[2] * t.coeff_count() * 3, sizeof(float), "choose a coarser --grid");
    auto g = t.to_dense(n[0], n[1], n[2]);
    ilf::write_shgrid(o->out, g);
    iblcli::emit(
        {{"tree", o->tree}, {"out", o->out}, {"resolution", {n[0], n[1], n[2]}}, {"bytes", g.data().size() * 4}}, [&] {
          fmt::print("wrote {} ({}x{}x{}, {:.2f} MB)\n", o->out, n[0], n[1], n[2], g.data().size() * 4 / 1048576.0);
        });
  });
}

void setup_synth(CLI::App& app) {
  auto* d = iblcli::app_owned<ilf::SynthDesc>();
  bool* pfm = iblcli::app_owned<bool>(!d->half);
  app.add_option("-o,--out", d->out_dir, "output folder (frames/ and sequence.json)")->required();
  app.add_option("--probes", d->probes, "number of probes")->capture_default_str()->check(CLI::Range(1, 1000000));
  app.add_option("--size", d->size, "mirror-ball frame size in pixels")
      ->capture_default_str()
      ->check(CLI::Range(8, 4096));
  app.add_option("--supersample", d->supersample, "sub-samples per pixel axis")
      ->capture_default_str()
      ->check(CLI::Range(1, 16));
  app.add_option("--seed", d->seed, "random positions seed")->capture_default_str();
  app.add_flag("--pfm", *pfm, "float PFM frames instead of half-float EXR");
  app.footer(
      "A closed-form light field (three emitting spheres outside a 1 m cube and a sky) captured by\n"
      "mirror balls at random positions in the cube: for tests, benchmarks and trying the pipeline.\n"
      "Example:\n  iblkit ilf synth --out synth --probes 50 --size 32");
  app.callback([d, pfm] {
    d->half = !*pfm;
    auto m = ilf::write_synthetic_sequence(ilf::AnalyticField::three_spheres(), *d, iblcli::progress_bar());
    iblcli::progress_done();
    iblcli::emit({{"manifest", m}, {"probes", d->probes}}, [&] { fmt::print("wrote {} ({} probes)\n", m, d->probes); });
  });
}

// The grid as three.js r187's LightProbeGridWebGL loads it (ilf/threejs_grid.h, docs/web.md).
void setup_export_threejs(CLI::App& app) {
  struct Opts {
    std::string grid, out, name = "grid";
  };
  auto* o = iblcli::app_owned<Opts>();
  app.add_option("grid", o->grid, ".shgrid or .shtree file (resampled at its fine resolution)")->required();
  app.add_option("-o,--out", o->out, "output folder (NAME.json and NAME_atlas.bin)")->required();
  app.add_option("--name", o->name, "base name of the two files")->capture_default_str();
  app.footer("Example:\n  iblkit ilf export-threejs room.shgrid --out web-grid");
  app.callback([o] {
    if (o->name.empty() || o->name.find_first_of("/\\") != std::string::npos)
      fail(ErrorKind::Value, "--name \"{}\": expected a plain file name", o->name);
    auto g = ilf::read_dense(o->grid);
    std::string json = ilf::write_threejs_grid(g, o->out, o->name);
    const auto& gd = g.grid();
    iblcli::emit({{"grid", o->grid},
                  {"out", json},
                  {"resolution", {gd.nx, gd.ny, gd.nz}},
                  {"bands_kept", std::min(g.bands(), 3)},
                  {"bands", g.bands()}},
                 [&] {
                   fmt::print("wrote {} and its atlas: {}x{}x{} probes, 3 of {} bands, atlas {}x{}x{} RGBA float32\n",
                              json, gd.nx, gd.ny, gd.nz, g.bands(), gd.nx, gd.ny,
                              ilf::kThreeAtlasVolumes * (gd.nz + 2 * ilf::kThreeAtlasPadding));
                 });
  });
}

void setup(CLI::App& app) {
  app.require_subcommand(1);
  app.footer(
      "Examples:\n  iblkit lab capture low-scene2 --grid 4,4,4 --mapping mirrorball --size 64 --out cap\n"
      "  iblkit ilf build cap/sequence.json --grid 16 --bands 5 --out room.shgrid\n"
      "  iblkit ilf query room.shgrid --at 0,1,0");
  setup_build(*app.add_subcommand("build", "Resample a probe sequence into an SH grid (.shgrid)"));
  setup_adapt(
      *app.add_subcommand("adapt", "Store a grid adaptively (.shtree): fine bricks only where coarser levels miss it"));
  setup_densify(*app.add_subcommand("densify", "Resample an adaptive grid (.shtree) into a dense .shgrid"));
  setup_query(*app.add_subcommand("query", "SH, irradiance, radiance and glossy response at a point of a grid"));
  setup_slice(*app.add_subcommand("slice", "Irradiance on a plane through the grid, as a picture"));
  setup_info(*app.add_subcommand("info", "Describe an .shgrid or .shtree"));
  setup_synth(*app.add_subcommand("synth", "Write a synthetic probe sequence of a closed-form light field"));
  setup_export_threejs(
      *app.add_subcommand("export-threejs", "Write the grid as three.js LightProbeGridWebGL loads it (atlas + JSON)"));
}

iblcli::Command reg("ilf", setup);

}  // namespace
