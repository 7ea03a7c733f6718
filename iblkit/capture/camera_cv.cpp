// OpenCV's side of capture/camera_solve.h: solvePnP, findChessboardCorners + cornerSubPix and
// calibrateCamera. Built into the "cv" plugin (libiblkit_cv.so) for the iblkit command and linked directly
// into the plugin's test binary (iblkit_cv_tests); either way it provides itself to
// capture::detail::cv_solver when its code is loaded.
//
// Pixels: iblkit's continuous coordinates put pixel i's centre at i + ½, OpenCV's at i; every pixel and
// principal point crosses here with a shift of ½.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#ifdef IBLKIT_HAVE_ARUCO
#include <opencv2/aruco/charuco.hpp>
#endif

#include "iblkit/capture/camera_solve.h"
#include "iblkit/core/error.h"

namespace ibl::capture {
namespace {

using geometry::Camera;

std::vector<cv::Point3d> object_points(const std::vector<Correspondence>& pts) {
  std::vector<cv::Point3d> o;
  for (const auto& p : pts) o.emplace_back(p.world.x, p.world.y, p.world.z);
  return o;
}
std::vector<cv::Point2d> image_points(const std::vector<Correspondence>& pts) {
  std::vector<cv::Point2d> o;
  for (const auto& p : pts) o.emplace_back(p.pixel.x - 0.5, p.pixel.y - 0.5);
  return o;
}

cv::Mat camera_matrix(const geometry::Intrinsics& k) {
  return (cv::Mat_<double>(3, 3) << k.fx, 0, k.cx - 0.5, 0, k.fy, k.cy - 0.5, 0, 0, 1);
}
cv::Mat dist_coeffs(const Camera& c) {
  const auto& d = c.distortion;
  if (!c.intrinsics) return cv::Mat::zeros(1, 5, CV_64F);
  return (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
}

// The plane through the points: centroid, and a right-handed basis (e1, e2, normal); coplanar when the
// smallest spread is below 1e-7 of the largest.
struct Plane {
  Eigen::Vector3d centroid;
  Eigen::Matrix3d basis;  // rows e1, e2, n
  bool coplanar = false;
};
Plane fit_plane(const std::vector<Correspondence>& pts) {
  Plane pl;
  pl.centroid.setZero();
  for (const auto& p : pts) pl.centroid += Eigen::Vector3d(p.world.x, p.world.y, p.world.z);
  pl.centroid /= static_cast<double>(pts.size());
  Eigen::MatrixXd a(pts.size(), 3);
  for (size_t i = 0; i < pts.size(); ++i)
    a.row(static_cast<Eigen::Index>(i)) = Eigen::Vector3d(pts[i].world.x, pts[i].world.y, pts[i].world.z) - pl.centroid;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinV);
  Eigen::Vector3d s = svd.singularValues();
  Eigen::Matrix3d v = svd.matrixV();
  Eigen::Vector3d e1 = v.col(0), e2 = v.col(1), n = e1.cross(e2);
  pl.basis.row(0) = e1;
  pl.basis.row(1) = e2;
  pl.basis.row(2) = n;
  pl.coplanar = s(2) <= 1e-7 * std::max(s(0), 1e-300);
  return pl;
}

// The iblkit camera of an OpenCV pose (X_cam = R X + t; camera x right, y down, z forward).
Camera camera_of_pose(const cv::Mat& rvec, const cv::Mat& tvec, const Camera& lens,
                      const std::vector<Correspondence>& pts) {
  cv::Mat rm;
  cv::Rodrigues(rvec, rm);
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = rm.at<double>(i, j);
  Eigen::Vector3d t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  Eigen::Vector3d eye = -r.transpose() * t, f = r.row(2).transpose(), up = -r.row(1).transpose();
  double depth = 0;
  for (const auto& p : pts) depth += (Eigen::Vector3d(p.world.x, p.world.y, p.world.z) - eye).dot(f);
  depth /= static_cast<double>(pts.size());
  if (!(depth > 1e-6)) depth = 1;
  Camera c = lens;
  c.eye = {eye.x(), eye.y(), eye.z()};
  c.target = {eye.x() + f.x() * depth, eye.y() + f.y() * depth, eye.z() + f.z() * depth};
  c.up = {up.x(), up.y(), up.z()};
  return c;
}

double rms_of(const std::vector<cv::Point3d>& obj, const std::vector<cv::Point2d>& img, const cv::Mat& k,
              const cv::Mat& d, const cv::Mat& rvec, const cv::Mat& tvec) {
  std::vector<cv::Point2d> proj;
  cv::projectPoints(obj, rvec, tvec, k, d, proj);
  double s = 0;
  for (size_t i = 0; i < img.size(); ++i) {
    cv::Point2d e = proj[i] - img[i];
    s += e.dot(e);
  }
  return std::sqrt(s / static_cast<double>(img.size()));
}

// The pose for fixed intrinsics k, d: IPPE for coplanar points, else EPnP refined by ITERATIVE
// (Levenberg–Marquardt); both followed by an LM refinement.
void pose(const std::vector<cv::Point3d>& obj, const std::vector<cv::Point2d>& img, const cv::Mat& k, const cv::Mat& d,
          bool coplanar, cv::Mat& rvec, cv::Mat& tvec) {
  bool ok;
  if (coplanar) {
    ok = cv::solvePnP(obj, img, k, d, rvec, tvec, false, cv::SOLVEPNP_IPPE);
  } else {
    ok = cv::solvePnP(obj, img, k, d, rvec, tvec, false, cv::SOLVEPNP_EPNP);
    if (ok) ok = cv::solvePnP(obj, img, k, d, rvec, tvec, true, cv::SOLVEPNP_ITERATIVE);
  }
  if (!ok) fail(ErrorKind::Value, "camera solve: OpenCV's solvePnP found no pose for these points");
  cv::solvePnPRefineLM(obj, img, k, d, rvec, tvec,
                       cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-12));
}

Solved cv_solve(const std::vector<Correspondence>& pts, const Camera& lens, LensMode mode) {
  auto obj = object_points(pts);
  auto img = image_points(pts);
  Plane pl = fit_plane(pts);
  Solved s;
  s.coplanar = pl.coplanar;
  cv::Mat rvec, tvec;
  try {
    if (mode == LensMode::Fixed) {
      cv::Mat k = camera_matrix(lens.effective_intrinsics()), d = dist_coeffs(lens);
      pose(obj, img, k, d, pl.coplanar, rvec, tvec);
      s.camera = camera_of_pose(rvec, tvec, lens, pts);
      return s;
    }
    // One focal length: a scan of vertical fields of view, then a golden-section search on the RMS error.
    const double w = lens.width, h = lens.height;
    auto focal_of = [&](double fov_deg) { return h / (2 * std::tan(fov_deg * kPi / 360)); };
    auto rms_at = [&](double f, cv::Mat& rv, cv::Mat& tv) {
      cv::Mat k = (cv::Mat_<double>(3, 3) << f, 0, w / 2 - 0.5, 0, f, h / 2 - 0.5, 0, 0, 1);
      cv::Mat d = cv::Mat::zeros(1, 5, CV_64F);
      try {
        pose(obj, img, k, d, pl.coplanar, rv, tv);
      } catch (const Error&) {
        return 1e300;
      }
      return rms_of(obj, img, k, d, rv, tv);
    };
    double best_fov = 0, best = 1e300;
    for (double fov = 10; fov <= 120; fov += 2) {
      cv::Mat rv, tv;
      double e = rms_at(focal_of(fov), rv, tv);
      if (e < best) best = e, best_fov = fov;
    }
    if (best >= 1e300) fail(ErrorKind::Value, "camera solve: OpenCV's solvePnP found no pose at any focal length");
    double lo = focal_of(std::min(best_fov + 2, 179.0)), hi = focal_of(std::max(best_fov - 2, 1.0));
    const double g = (std::sqrt(5.0) - 1) / 2;
    double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    cv::Mat rv, tv;
    double f1 = rms_at(x1, rv, tv), f2 = rms_at(x2, rv, tv);
    for (int it = 0; it < 100 && hi - lo > 1e-9 * hi; ++it) {
      if (f1 < f2) {
        hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = rms_at(x1, rv, tv);
      } else {
        lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = rms_at(x2, rv, tv);
      }
    }
    double f = (lo + hi) / 2;
    rms_at(f, rvec, tvec);
    Camera pin = lens;
    pin.intrinsics.reset();
    pin.distortion = {};
    pin.fov_y_deg = 2 * std::atan(h / (2 * f)) * 180 / kPi;
    s.camera = camera_of_pose(rvec, tvec, pin, pts);
    return s;
  } catch (const cv::Exception& e) {
    fail(ErrorKind::Value, "camera solve: OpenCV: {}", e.what());
  }
}

// 8 bits for OpenCV: scaled so that the 99.5th percentile is white, with a 1/2.2 gamma (a linear
// photograph's dark squares would otherwise all be 0 or 1).
cv::Mat eight_bits(const Image& grey) {
  std::vector<float> v(grey.data(), grey.data() + grey.size());
  for (float& x : v)
    if (!std::isfinite(x) || x < 0) x = 0;
  std::vector<float> sorted = v;
  size_t q = std::min(sorted.size() - 1, static_cast<size_t>(0.995 * static_cast<double>(sorted.size())));
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(q), sorted.end());
  double top = std::max(1e-12, static_cast<double>(sorted[q]));
  cv::Mat g8(grey.height(), grey.width(), CV_8U);
  for (int y = 0; y < grey.height(); ++y)
    for (int x = 0; x < grey.width(); ++x) {
      double t = std::min(1.0, v[static_cast<size_t>(y) * grey.width() + x] / top);
      g8.at<uint8_t>(y, x) = static_cast<uint8_t>(std::lround(255 * std::pow(t, 1 / 2.2)));
    }
  return g8;
}

std::optional<std::vector<Vec2>> cv_find_chessboard(const Image& grey, int cols, int rows) {
  const cv::Mat g8 = eight_bits(grey);
  std::vector<cv::Point2f> corners;
  cv::Size pattern(cols, rows);
  try {
    bool ok =
        cv::findChessboardCorners(g8, pattern, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
    if (!ok || corners.size() != static_cast<size_t>(cols * rows)) {
      // The sector-based detector finds boards the classic one misses (small, oblique ones), with its own
      // sub-pixel corners.
      corners.clear();
      ok = cv::findChessboardCornersSB(g8, pattern, corners, cv::CALIB_CB_ACCURACY);
      if (!ok || corners.size() != static_cast<size_t>(cols * rows)) return std::nullopt;
      std::vector<Vec2> out;
      for (const auto& c : corners) out.push_back({c.x + 0.5, c.y + 0.5});
      return out;
    }
    // The refinement window: a third of the smallest corner spacing, 2..11 px half-width.
    double spacing = 1e300;
    for (int b = 0; b < rows; ++b)
      for (int a = 0; a + 1 < cols; ++a)
        spacing = std::min<double>(spacing, cv::norm(corners[b * cols + a + 1] - corners[b * cols + a]));
    int half = std::clamp(static_cast<int>(spacing / 3), 2, 11);
    cv::cornerSubPix(g8, corners, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
  } catch (const cv::Exception& e) {
    fail(ErrorKind::Value, "board detection: OpenCV: {}", e.what());
  }
  std::vector<Vec2> out;
  for (const auto& c : corners) out.push_back({c.x + 0.5, c.y + 0.5});
  return out;
}

Calibrated cv_calibrate(const std::vector<std::vector<Correspondence>>& views, int width, int height) {
  std::vector<std::vector<cv::Point3f>> obj;
  std::vector<std::vector<cv::Point2f>> img;
  std::vector<Plane> planes;
  for (const auto& view : views) {
    Plane pl = fit_plane(view);
    if (!pl.coplanar) fail(ErrorKind::Value, "camera calibrate: a view's board points are not coplanar");
    std::vector<cv::Point3f> o;
    std::vector<cv::Point2f> im;
    for (const auto& p : view) {
      Eigen::Vector3d q = pl.basis * (Eigen::Vector3d(p.world.x, p.world.y, p.world.z) - pl.centroid);
      o.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()), 0.0f);
      im.emplace_back(static_cast<float>(p.pixel.x - 0.5), static_cast<float>(p.pixel.y - 0.5));
    }
    obj.push_back(o);
    img.push_back(im);
    planes.push_back(pl);
  }
  cv::Mat k, d;
  std::vector<cv::Mat> rvecs, tvecs;
  Calibrated c;
  std::vector<double> per_view;
  try {
    cv::Mat sd_in, sd_ex, per;
    c.rms_px = cv::calibrateCamera(obj, img, cv::Size(width, height), k, d, rvecs, tvecs, sd_in, sd_ex, per, 0,
                                   cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-12));
    for (int i = 0; i < per.rows; ++i) c.per_view_rms_px.push_back(per.at<double>(i));
    for (int i = 0; i < std::min(9, sd_in.rows); ++i) c.std_dev[static_cast<size_t>(i)] = sd_in.at<double>(i);
  } catch (const cv::Exception& e) {
    fail(ErrorKind::Value, "camera calibrate: OpenCV: {}", e.what());
  }
  Camera lens;
  lens.width = width;
  lens.height = height;
  lens.intrinsics =
      geometry::Intrinsics{k.at<double>(0, 0), k.at<double>(1, 1), k.at<double>(0, 2) + 0.5, k.at<double>(1, 2) + 0.5};
  lens.distortion = {d.at<double>(0), d.at<double>(1), d.at<double>(2), d.at<double>(3), d.at<double>(4)};
  lens.fov_y_deg = 2 * std::atan(height / (2 * lens.intrinsics->fy)) * 180 / kPi;
  {  // Parameters the photographs leave loose (calibrateCamera's own standard deviations).
    static const char* names[9] = {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};
    const double value[9] = {k.at<double>(0, 0),       k.at<double>(1, 1), k.at<double>(0, 2) + 0.5,
                             k.at<double>(1, 2) + 0.5, d.at<double>(0),    d.at<double>(1),
                             d.at<double>(2),          d.at<double>(3),    d.at<double>(4)};
    const double f = k.at<double>(0, 0);
    const double limit[9] = {0.01 * f, 0.01 * f, 0.01 * f, 0.01 * f, 0.05, 0.05, 0.005, 0.005, 0.05};
    for (int i = 0; i < 9; ++i)
      if (c.std_dev[static_cast<size_t>(i)] > limit[i])
        c.warnings.push_back(
            fmt::format("{} = {:.4g} ± {:.3g}: the photographs do not pin it down (tilt the board, "
                        "fill the corners of the frame, or take more photographs)",
                        names[i], value[i], c.std_dev[static_cast<size_t>(i)]));
  }
  // The first view's pose, back in world coordinates: X_cam = R B (X − c) + t.
  cv::Mat rm;
  cv::Rodrigues(rvecs[0], rm);
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = rm.at<double>(i, j);
  Eigen::Matrix3d rw = r * planes[0].basis;
  Eigen::Vector3d t(tvecs[0].at<double>(0), tvecs[0].at<double>(1), tvecs[0].at<double>(2));
  Eigen::Vector3d tw = t - rw * planes[0].centroid;
  Eigen::AngleAxisd aa(rw);
  Eigen::Vector3d rv = aa.angle() * aa.axis();
  cv::Mat rvec = (cv::Mat_<double>(3, 1) << rv.x(), rv.y(), rv.z());
  cv::Mat tvec = (cv::Mat_<double>(3, 1) << tw.x(), tw.y(), tw.z());
  c.camera = camera_of_pose(rvec, tvec, lens, views[0]);
  return c;
}

#ifdef IBLKIT_HAVE_ARUCO
cv::Ptr<cv::aruco::CharucoBoard> charuco_board(const Board& b) {
  return cv::aruco::CharucoBoard::create(b.cols + 1, b.rows + 1, static_cast<float>(b.square),
                                         static_cast<float>(b.marker),
                                         cv::aruco::getPredefinedDictionary(b.dictionary));
}

// Two tone maps of the photograph: the 8-bit one the chessboard gets (99.5th percentile white, 1/2.2 gamma), and its
// logarithm over the same range (a marker half in a pool of light and half out of it reads in one or the other).
std::vector<cv::Mat> marker_views(const Image& grey) {
  cv::Mat g8 = eight_bits(grey), lg(g8.rows, g8.cols, CV_8U);
  for (int y = 0; y < g8.rows; ++y)
    for (int x = 0; x < g8.cols; ++x) {
      const double t = std::pow(g8.at<uint8_t>(y, x) / 255.0, 2.2);  // back to linear over the white point
      lg.at<uint8_t>(y, x) =
          static_cast<uint8_t>(std::lround(255 * std::max(0.0, 1 + std::log2(std::max(t, 1e-4)) / 8)));
    }
  return {g8, lg};
}

std::vector<std::pair<int, Vec2>> cv_find_charuco(const Image& grey, const Board& b) {
  std::vector<std::pair<int, Vec2>> out;
  try {
    const auto board = charuco_board(b);
    const auto params = cv::aruco::DetectorParameters::create();
    params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
    const std::vector<cv::Mat> views = marker_views(grey);
    // The markers each tone map finds, the first one's where both find one.
    std::vector<std::vector<cv::Point2f>> marker_corners;
    std::vector<int> marker_ids;
    for (const cv::Mat& g : views) {
      std::vector<std::vector<cv::Point2f>> corners, rejected;
      std::vector<int> ids;
      cv::aruco::detectMarkers(g, board->dictionary, corners, ids, params, rejected);
      for (size_t k = 0; k < ids.size(); ++k)
        if (std::find(marker_ids.begin(), marker_ids.end(), ids[k]) == marker_ids.end()) {
          marker_ids.push_back(ids[k]);
          marker_corners.push_back(corners[k]);
        }
    }
    if (marker_ids.empty()) return out;
    std::vector<cv::Point2f> corners;
    std::vector<int> ids;
    cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, views[0], board, corners, ids);
    // Each corner refined again in a window that stays inside the white margin between it and the markers around
    // it ((square − marker) / 2 of the board, 80 % of it in pixels, 2..11 px): OpenCV's own window reaches the
    // markers' black borders on a board seen small, and they pull the corner (2.6 px RMS on the lab's 640×480 plate).
    double spacing = 1e300;
    for (size_t i = 0; i < ids.size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if (std::abs(ids[i] - ids[j]) == 1 && ids[i] / b.cols == ids[j] / b.cols)
          spacing = std::min<double>(spacing, cv::norm(corners[i] - corners[j]));
    if (spacing < 1e300 && !corners.empty()) {
      const int half = std::clamp(static_cast<int>(0.8 * spacing * (b.square - b.marker) / (2 * b.square)), 2, 11);
      cv::cornerSubPix(views[0], corners, cv::Size(half, half), cv::Size(-1, -1),
                       cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 60, 1e-3));
    }
    // Each corner checked against the markers beside it: a marker's four corners map its square's plane into the
    // image (a homography), which puts the ChArUco corner where that marker says it is. A corner further than
    // max(3 px, a fifth of the spacing) from what a marker beside it says, or whose two markers disagree by as much,
    // is left out: a marker outlined wrong (half in a pool of light) and a corner pulled off by an edge through its
    // window show so, even where too few corners are left for the pose to tell (the lab's board half in the pool:
    // 94 mm off without it, 1.3 mm with). Tighter (2 px, 12 %) lost good corners on the lab's noisy 640×480 plate:
    // the markers there are 18 px, their outlines a pixel or two off.
    const double tol = std::max(3.0, spacing < 1e300 ? 0.2 * spacing : 3.0);
    std::vector<cv::Mat> homography(marker_ids.size());
    std::vector<cv::Point2f> centre(marker_ids.size());
    for (size_t m = 0; m < marker_ids.size(); ++m) {
      const auto at = std::find(board->ids.begin(), board->ids.end(), marker_ids[m]);
      if (at == board->ids.end()) continue;
      const std::vector<cv::Point3f>& obj = board->objPoints[static_cast<size_t>(at - board->ids.begin())];
      std::vector<cv::Point2f> plane;
      for (const auto& q : obj) plane.emplace_back(q.x, q.y);
      centre[m] = 0.25f * (plane[0] + plane[1] + plane[2] + plane[3]);
      homography[m] = cv::getPerspectiveTransform(plane, marker_corners[m]);
    }
    const double reach = 0.75 * b.square;  // a light square beside a corner has its centre 0.707 squares away
    for (size_t k = 0; k < ids.size(); ++k) {
      const cv::Point3f c3 = board->chessboardCorners[static_cast<size_t>(ids[k])];
      const cv::Point2f c2(c3.x, c3.y);
      std::vector<cv::Point2f> said;
      for (size_t m = 0; m < marker_ids.size(); ++m) {
        if (homography[m].empty() || cv::norm(centre[m] - c2) > reach) continue;
        std::vector<cv::Point2f> src{c2}, dst;
        cv::perspectiveTransform(src, dst, homography[m]);
        said.push_back(dst[0]);
      }
      bool ok = true;
      for (size_t i = 0; i < said.size() && ok; ++i) {
        ok = cv::norm(said[i] - corners[k]) <= tol;
        for (size_t j = 0; j < i && ok; ++j) ok = cv::norm(said[i] - said[j]) <= tol;
      }
      if (ok) out.push_back({ids[k], {corners[k].x + 0.5, corners[k].y + 0.5}});
    }
  } catch (const cv::Exception& e) {
    fail(ErrorKind::Value, "{}: OpenCV: {}", b.describe(), e.what());
  }
  return out;
}

Image cv_draw_charuco(const Board& b, int px) {
  cv::Mat img;
  charuco_board(b)->draw(cv::Size((b.cols + 1) * px, (b.rows + 1) * px), img, 0, 1);
  Image out(img.cols, img.rows, 1);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) out.at(x, y, 0) = img.at<uint8_t>(y, x) / 255.0f;
  return out;
}
const detail::CvSolver kSolver{cv_solve, cv_find_chessboard, cv_calibrate, cv_find_charuco, cv_draw_charuco};
#else
const detail::CvSolver kSolver{cv_solve, cv_find_chessboard, cv_calibrate, nullptr, nullptr};
#endif
[[maybe_unused]] const bool kProvided = (detail::cv_solver.provide(&kSolver), true);

}  // namespace
}  // namespace ibl::capture
