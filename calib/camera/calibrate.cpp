#include "rigcal/camera/calibrate.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <fmt/format.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <stdexcept>

#include "rigcal/camera/lens.h"
#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"

namespace rigcal::camera {
namespace {

// Projection with the intrinsics block k = [fx fy cx cy d...] (radtan: k1 k2 p1 p2 [k3];
// equidistant: k1..k4), OpenCV's formulas (calib/camera/lens.h).
template <typename T>
void project_with(const T* k, bool radtan, int n_coeffs, const T* p, T* uv) {
  const T x = p[0] / p[2], y = p[1] / p[2];
  const T r2 = x * x + y * y;
  T xd, yd;
  if (radtan) {
    const T k3 = n_coeffs > 4 ? k[8] : T(0.0);
    const T radial = T(1.0) + r2 * (k[4] + r2 * (k[5] + r2 * k3));
    xd = x * radial + T(2.0) * k[6] * x * y + k[7] * (r2 + T(2.0) * x * x);
    yd = y * radial + k[6] * (r2 + T(2.0) * y * y) + T(2.0) * k[7] * x * y;
  } else if (r2 < T(1e-16)) {
    xd = x;
    yd = y;
  } else {
    using std::atan;
    using std::sqrt;
    const T r = sqrt(r2);
    const T th = atan(r), t2 = th * th;
    const T thd = th * (T(1.0) + t2 * (k[4] + t2 * (k[5] + t2 * (k[6] + t2 * k[7]))));
    xd = x * thd / r;
    yd = y * thd / r;
  }
  uv[0] = k[0] * xd + k[2];
  uv[1] = k[1] * yd + k[3];
}

// Projected minus observed, px.
template <typename T>
bool residual(const T* k, bool radtan, int n_coeffs, const Eigen::Matrix<T, 3, 1>& p,
              const Eigen::Vector2d& observed, T* r) {
  T uv[2];
  project_with(k, radtan, n_coeffs, p.data(), uv);
  r[0] = uv[0] - T(observed.x());
  r[1] = uv[1] - T(observed.y());
  return true;
}

// The flat board's points and, for its warp (target.h), the two parabolas at each of them.
struct BoardPoints {
  std::vector<Eigen::Vector3d> p;
  std::vector<Eigen::Vector2d> warp_basis;
};

BoardPoints board_points(const Target& target) {
  BoardPoints b{object_points(target), {}};
  for (const Eigen::Vector3d& p : b.p)
    b.warp_basis.push_back(board_warp_basis(target, p.x(), p.y()));
  return b;
}

// The corner on the board, warped by w (held at zero unless the warp is solved).
template <typename T>
Eigen::Matrix<T, 3, 1> on_board(const Eigen::Vector3d& p_board, const Eigen::Vector2d& basis,
                                const T* w) {
  Eigen::Matrix<T, 3, 1> p = p_board.cast<T>();
  p.z() += w[0] * basis.x() + w[1] * basis.y();
  return p;
}

// A corner seen by camera 0: intrinsics, board rotation and translation in camera 0, warp.
template <int NK>
struct Cam0Error {
  Eigen::Vector3d p_board;
  Eigen::Vector2d warp_basis, observed;
  bool radtan;
  template <typename T>
  bool operator()(const T* k, const T* q_board, const T* t_board, const T* w, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_board);
    const Eigen::Matrix<T, 3, 1> p =
        q * on_board(p_board, warp_basis, w) + Eigen::Map<const Eigen::Matrix<T, 3, 1>>(t_board);
    return residual(k, radtan, NK - 4, p, observed, r);
  }
};

// A corner seen by camera c: also T_c_0.
template <int NK>
struct CamCError {
  Eigen::Vector3d p_board;
  Eigen::Vector2d warp_basis, observed;
  bool radtan;
  template <typename T>
  bool operator()(const T* k, const T* q_board, const T* t_board, const T* w, const T* q_c0,
                  const T* t_c0, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> qb(q_board), qc(q_c0);
    const Eigen::Matrix<T, 3, 1> p0 =
        qb * on_board(p_board, warp_basis, w) + Eigen::Map<const Eigen::Matrix<T, 3, 1>>(t_board);
    const Eigen::Matrix<T, 3, 1> p = qc * p0 + Eigen::Map<const Eigen::Matrix<T, 3, 1>>(t_c0);
    return residual(k, radtan, NK - 4, p, observed, r);
  }
};

template <int NK>
ceres::CostFunction* make_cost(int camera, const Eigen::Vector3d& p, const Eigen::Vector2d& basis,
                               const Eigen::Vector2d& uv, bool radtan) {
  if (camera == 0)
    return new ceres::AutoDiffCostFunction<Cam0Error<NK>, 2, NK, 4, 3, 2>(
        new Cam0Error<NK>{p, basis, uv, radtan});
  return new ceres::AutoDiffCostFunction<CamCError<NK>, 2, NK, 4, 3, 2, 4, 3>(
      new CamCError<NK>{p, basis, uv, radtan});
}

struct Pose {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  SE3 se3() const { return SE3::from_quaternion(q, t); }
  static Pose from(const SE3& T) { return {T.quaternion(), T.t}; }
};

SE3 from_rvec_tvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  SE3 T;
  cv::cv2eigen(R, T.R);
  cv::Vec3d t(tvec);
  T.t = Eigen::Vector3d(t[0], t[1], t[2]);
  return T;
}

double mad_sigma(std::vector<double> v) {
  if (v.empty()) return 0.0;
  for (double& x : v) x = std::abs(x);
  return 1.4826 * median(std::move(v));
}

// The distortion model as the cost functions take it: the intrinsics block is
// [fx fy cx cy d...] with n_coeffs distortion coefficients.
struct Lens {
  bool radtan = true;
  int n_coeffs = 4;
  int intrinsics_size() const { return 4 + n_coeffs; }
};
using Lenses = std::vector<Lens>;  // one a camera

// The parameters of the joint problem, changed in place by the solves.
struct Parameters {
  std::vector<std::vector<double>> intr;   // per camera: its intrinsics block
  std::vector<Pose> cam_pose;              // per camera: T_c_0 (camera 0: identity, not solved)
  std::vector<std::optional<Pose>> board;  // per frame: T_0_board (none: no camera saw it)
  Eigen::Vector2d warp = Eigen::Vector2d::Zero();  // the board's, m (target.h)
  bool solve_warp = false;                         // else held at zero
  bool hold_cameras = false;  // intrinsics and camera poses held: boards (and warp) alone
};

// Throws rigcal::Error without cameras or when they differ in frame count.
void check_frames_pair_up(const std::vector<CameraInput>& cams) {
  if (cams.empty()) throw Error("no camera to calibrate");
  const size_t n_frames = cams[0].frames.size();
  for (const CameraInput& c : cams) {
    if (c.frames.size() != n_frames) {
      throw Error(fmt::format("camera {} has {} frames, camera {} has {}: frames must pair up",
                              c.name, c.frames.size(), cams[0].name, n_frames));
    }
  }
}

// Throws rigcal::Error on a radtan model of neither 4 nor 5 coefficients.
Lens lens_of(rig::DistortionModel model, int radtan_coefficients) {
  const bool radtan = model == rig::DistortionModel::radtan;
  const int n_coeffs = radtan ? radtan_coefficients : 4;
  if (radtan && n_coeffs != 4 && n_coeffs != 5) throw Error("radtan takes 4 or 5 coefficients");
  return {radtan, n_coeffs};
}

// Each camera's lens: its own (CalibrationOptions::per_camera) or the common one. Throws
// rigcal::Error when per_camera does not name one lens a camera.
Lenses lenses_of(const CalibrationOptions& opt, size_t n_cams) {
  if (!opt.per_camera.empty() && opt.per_camera.size() != n_cams)
    throw Error(fmt::format("{} lens models for {} cameras", opt.per_camera.size(), n_cams));
  Lenses lenses;
  for (size_t c = 0; c < n_cams; ++c) {
    lenses.push_back(opt.per_camera.empty()
                         ? lens_of(opt.model, opt.radtan_coefficients)
                         : lens_of(opt.per_camera[c].model, opt.per_camera[c].radtan_coefficients));
  }
  return lenses;
}

// One camera alone by OpenCV's calibration: its initial intrinsics block, and in T_c_board the
// board pose of every frame with a usable detection (6 corners or more). Throws rigcal::Error
// with fewer than min_views such frames or when the calibration diverges.
std::vector<double> initial_intrinsics(const CameraInput& cam,
                                       const std::vector<Eigen::Vector3d>& object, const Lens& lens,
                                       int min_views, std::vector<std::optional<SE3>>& T_c_board) {
  const size_t n_frames = cam.frames.size();
  const bool radtan = lens.radtan;
  const int n_coeffs = lens.n_coeffs;
  std::vector<std::vector<cv::Point3f>> obj;
  std::vector<std::vector<cv::Point2f>> img;
  std::vector<size_t> frame_of;
  for (size_t f = 0; f < n_frames; ++f) {
    const Detection& d = cam.frames[f];
    if (!d.found || d.pixels.size() < 6) continue;
    obj.emplace_back();
    img.emplace_back();
    for (size_t i = 0; i < d.pixels.size(); ++i) {
      const Eigen::Vector3d& p = object[d.point_ids[i]];
      obj.back().emplace_back(p.x(), p.y(), p.z());
      img.back().emplace_back(d.pixels[i].x(), d.pixels[i].y());
    }
    frame_of.push_back(f);
  }
  if (static_cast<int>(obj.size()) < min_views) {
    throw Error(fmt::format("camera {}: {} usable views of the target; at least {} are needed",
                            cam.name, obj.size(), min_views));
  }
  const cv::Size size(cam.width, cam.height);
  cv::Mat K = cv::Mat::eye(3, 3, CV_64F), D;
  std::vector<cv::Mat> rvecs, tvecs;
  // Pinhole with radial k1 k2 (no tangential, no k3) is a safe start for both models: Ceres
  // then frees every coefficient. No interactive guesses, no NaN seeds.
  const int flags = cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3;
  cv::calibrateCamera(obj, img, size, K, D, rvecs, tvecs, flags,
                      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-9));
  std::vector<double> k = {K.at<double>(0, 0), K.at<double>(1, 1), K.at<double>(0, 2),
                           K.at<double>(1, 2)};
  if (radtan) {
    k.insert(k.end(), {D.at<double>(0), D.at<double>(1), 0.0, 0.0});
    if (n_coeffs == 5) k.push_back(0.0);
  } else {
    k.insert(k.end(), {0.0, 0.0, 0.0, 0.0});
  }
  for (double v : k) {
    if (!std::isfinite(v))
      throw Error(fmt::format("camera {}: the initial calibration diverged", cam.name));
  }
  T_c_board.assign(n_frames, std::nullopt);
  for (size_t i = 0; i < frame_of.size(); ++i)
    T_c_board[frame_of[i]] = from_rvec_tvec(rvecs[i], tvecs[i]);
  return k;
}

// T_c_0 of every camera (camera 0: identity): the average over the frames both see.
std::vector<Pose> camera_poses(const std::vector<CameraInput>& cams,
                               const std::vector<std::vector<std::optional<SE3>>>& T_c_board) {
  const size_t n_frames = cams[0].frames.size();
  std::vector<Pose> cam_pose(cams.size());
  for (size_t c = 1; c < cams.size(); ++c) {
    Eigen::Vector4d q_sum = Eigen::Vector4d::Zero();
    std::vector<double> tx, ty, tz;
    Eigen::Quaterniond q_ref = Eigen::Quaterniond::Identity();
    for (size_t f = 0; f < n_frames; ++f) {
      if (!T_c_board[0][f] || !T_c_board[c][f]) continue;
      const SE3 T = *T_c_board[c][f] * T_c_board[0][f]->inverse();
      Eigen::Quaterniond q = T.quaternion();
      if (tx.empty()) q_ref = q;
      if (q.coeffs().dot(q_ref.coeffs()) < 0) q.coeffs() *= -1;
      q_sum += q.coeffs();
      tx.push_back(T.t.x()), ty.push_back(T.t.y()), tz.push_back(T.t.z());
    }
    if (tx.empty())
      throw Error(
          fmt::format("cameras {} and {} never see the target in the same frame: their relative "
                      "pose is unknown",
                      cams[0].name, cams[c].name));
    cam_pose[c].q.coeffs() = q_sum.normalized();  // the normalized mean of aligned quaternions
    cam_pose[c].t = Eigen::Vector3d(median(tx), median(ty), median(tz));
  }
  return cam_pose;
}

// T_0_board of every frame: camera 0's, else that of the first other camera that saw it.
std::vector<std::optional<Pose>> board_poses(
    const std::vector<std::vector<std::optional<SE3>>>& T_c_board,
    const std::vector<Pose>& cam_pose) {
  const size_t n_frames = T_c_board[0].size();
  std::vector<std::optional<Pose>> board(n_frames);
  for (size_t f = 0; f < n_frames; ++f) {
    if (T_c_board[0][f]) {
      board[f] = Pose::from(*T_c_board[0][f]);
      continue;
    }
    for (size_t c = 1; c < cam_pose.size(); ++c) {
      if (T_c_board[c][f]) {
        board[f] = Pose::from(cam_pose[c].se3().inverse() * *T_c_board[c][f]);
        break;
      }
    }
  }
  return board;
}

// One residual a detected corner of a frame with a board pose.
std::vector<CornerResidual> corner_residuals(const std::vector<CameraInput>& cams,
                                             const std::vector<std::optional<Pose>>& board) {
  std::vector<CornerResidual> residuals;
  for (size_t c = 0; c < cams.size(); ++c) {
    for (size_t f = 0; f < cams[c].frames.size(); ++f) {
      const Detection& d = cams[c].frames[f];
      if (!d.found || !board[f]) continue;
      for (size_t i = 0; i < d.pixels.size(); ++i) {
        CornerResidual cr;
        cr.camera = static_cast<int>(c);
        cr.frame = static_cast<int>(f);
        cr.point = d.point_ids[i];
        cr.observed = d.pixels[i];
        residuals.push_back(cr);
      }
    }
  }
  return residuals;
}

// One solve of the joint problem over the inlier corners, in `problem` (robust: Huber loss of
// huber_px). Throws rigcal::Error when the solution is not usable.
void solve(const std::vector<CornerResidual>& residuals, const BoardPoints& object,
           const Lenses& lenses, bool robust, double huber_px, Parameters& x,
           ceres::Problem& problem) {
  std::vector<std::vector<double>>& intr = x.intr;
  std::vector<Pose>& cam_pose = x.cam_pose;
  std::vector<std::optional<Pose>>& board = x.board;
  for (const CornerResidual& cr : residuals) {
    if (cr.outlier) continue;
    const Eigen::Vector3d& p = object.p[cr.point];
    const Eigen::Vector2d& basis = object.warp_basis[cr.point];
    const bool radtan = lenses[cr.camera].radtan;
    ceres::CostFunction* cost = lenses[cr.camera].intrinsics_size() == 8
                                    ? make_cost<8>(cr.camera, p, basis, cr.observed, radtan)
                                    : make_cost<9>(cr.camera, p, basis, cr.observed, radtan);
    ceres::LossFunction* loss = robust ? new ceres::HuberLoss(huber_px) : nullptr;
    Pose& b = *board[cr.frame];
    if (cr.camera == 0) {
      problem.AddResidualBlock(cost, loss, intr[0].data(), b.q.coeffs().data(), b.t.data(),
                               x.warp.data());
    } else {
      Pose& cp = cam_pose[cr.camera];
      problem.AddResidualBlock(cost, loss, intr[cr.camera].data(), b.q.coeffs().data(), b.t.data(),
                               x.warp.data(), cp.q.coeffs().data(), cp.t.data());
    }
  }
  if (!x.solve_warp && problem.HasParameterBlock(x.warp.data()))
    problem.SetParameterBlockConstant(x.warp.data());
  for (auto& b : board) {
    if (b && problem.HasParameterBlock(b->q.coeffs().data())) {
      problem.SetManifold(b->q.coeffs().data(), new ceres::EigenQuaternionManifold);
    }
  }
  for (size_t c = 1; c < cam_pose.size(); ++c) {
    if (problem.HasParameterBlock(cam_pose[c].q.coeffs().data())) {
      problem.SetManifold(cam_pose[c].q.coeffs().data(), new ceres::EigenQuaternionManifold);
      if (x.hold_cameras) {
        problem.SetParameterBlockConstant(cam_pose[c].q.coeffs().data());
        problem.SetParameterBlockConstant(cam_pose[c].t.data());
      }
    }
  }
  for (std::vector<double>& k : intr) {
    if (x.hold_cameras && problem.HasParameterBlock(k.data()))
      problem.SetParameterBlockConstant(k.data());
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::SPARSE_SCHUR;
  so.max_num_iterations = 200;
  so.function_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  so.num_threads = 1;  // deterministic sums: the same corners give the same calibration
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  if (!summary.IsSolutionUsable())
    throw Error("the calibration solve failed: " + summary.BriefReport());
}

// Every corner's residual (outliers too) at the parameters x.
void update_residuals(std::vector<CornerResidual>& residuals, const BoardPoints& object,
                      const Lenses& lenses, const Parameters& x) {
  for (CornerResidual& cr : residuals) {
    const Pose& b = *x.board[cr.frame];
    Eigen::Vector3d p =
        b.q * on_board(object.p[cr.point], object.warp_basis[cr.point], x.warp.data()) + b.t;
    if (cr.camera > 0) p = x.cam_pose[cr.camera].q * p + x.cam_pose[cr.camera].t;
    Eigen::Vector2d uv;
    const Lens& lens = lenses[cr.camera];
    project_with(x.intr[cr.camera].data(), lens.radtan, lens.n_coeffs, p.data(), uv.data());
    cr.residual = uv - cr.observed;
  }
}

// Robust solves, each followed by flagging the corners with a coordinate beyond
// outlier_k_sigma robust sigmas, until none is flagged or max_rejection_rounds.
void reject_outliers(std::vector<CornerResidual>& residuals, const BoardPoints& object,
                     const Lenses& lenses, const CalibrationOptions& opt, Parameters& x) {
  for (int round = 0; round < opt.max_rejection_rounds; ++round) {
    ceres::Problem problem;
    solve(residuals, object, lenses, true, opt.huber_px, x, problem);
    update_residuals(residuals, object, lenses, x);
    std::vector<double> coords;
    for (const CornerResidual& cr : residuals) {
      if (!cr.outlier) coords.push_back(cr.residual.x()), coords.push_back(cr.residual.y());
    }
    const double sigma = mad_sigma(coords);
    size_t dropped = 0;
    for (CornerResidual& cr : residuals) {
      if (!cr.outlier && cr.residual.cwiseAbs().maxCoeff() > opt.outlier_k_sigma * sigma)
        cr.outlier = true, ++dropped;
    }
    if (dropped == 0) break;
  }
}

// The residual statistics of the inliers, the parameter count and the noise level.
void fit_statistics(CalibrationResult& res, const Parameters& x) {
  double sse = 0.0;
  size_t n_in = 0;
  for (const CornerResidual& cr : res.residuals) {
    if (cr.outlier) {
      ++res.n_outliers;
      continue;
    }
    sse += cr.residual.squaredNorm();
    ++n_in;
  }
  res.rms_2d_px = std::sqrt(sse / n_in);
  res.rms_coord_px = std::sqrt(sse / (2.0 * n_in));
  res.n_residuals = 2 * n_in;
  res.n_parameters = 6 * (x.intr.size() - 1);
  for (const std::vector<double>& k : x.intr) res.n_parameters += k.size();
  for (const auto& b : x.board) res.n_parameters += b ? 6 : 0;
  res.n_parameters += x.solve_warp ? 2 : 0;
  const double dof = static_cast<double>(res.n_residuals) - static_cast<double>(res.n_parameters);
  res.noise_sigma_px = std::sqrt(sse / std::max(1.0, dof));
}

// The covariance of intrinsics, camera poses and board poses (res.covariance,
// res.board_covariance_index), scaled by the estimated noise; a note when it cannot be computed.
void add_covariance(CalibrationResult& res, ceres::Problem& problem, Parameters& x) {
  const size_t n_cams = x.intr.size();
  const size_t n_frames = x.board.size();
  std::vector<std::vector<double>>& intr = x.intr;
  std::vector<Pose>& cam_pose = x.cam_pose;
  std::vector<std::optional<Pose>>& board = x.board;
  std::vector<const double*> blocks;
  int n_cov = 0;
  for (size_t c = 0; c < n_cams; ++c) {
    blocks.push_back(intr[c].data());
    res.intrinsics_covariance_index.push_back(n_cov);
    n_cov += static_cast<int>(intr[c].size());
  }
  res.pose_covariance_index.assign(n_cams, -1);
  for (size_t c = 1; c < n_cams; ++c) {
    blocks.push_back(cam_pose[c].q.coeffs().data());
    blocks.push_back(cam_pose[c].t.data());
    res.pose_covariance_index[c] = n_cov;
    n_cov += 6;
  }
  res.board_covariance_index.assign(n_frames, -1);
  for (size_t f = 0; f < n_frames; ++f) {
    if (!board[f] || !problem.HasParameterBlock(board[f]->q.coeffs().data())) continue;
    res.board_covariance_index[f] = n_cov;
    n_cov += 6;
    blocks.push_back(board[f]->q.coeffs().data());
    blocks.push_back(board[f]->t.data());
  }
  if (x.solve_warp) {
    res.warp_covariance_index = n_cov;
    n_cov += 2;
    blocks.push_back(x.warp.data());
  }
  // Sparse QR first (fast on hundreds of board poses); dense SVD, which copes with a rank-deficient
  // problem, when it fails.
  res.covariance = Eigen::MatrixXd::Zero(n_cov, n_cov);
  bool have_cov = false;
  for (const ceres::CovarianceAlgorithmType algorithm : {ceres::SPARSE_QR, ceres::DENSE_SVD}) {
    ceres::Covariance::Options co;
    co.algorithm_type = algorithm;
    co.null_space_rank = algorithm == ceres::DENSE_SVD ? -1 : 0;
    co.num_threads = 1;
    ceres::Covariance covariance(co);
    if (!covariance.Compute(blocks, &problem)) continue;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> cov(n_cov, n_cov);
    have_cov = covariance.GetCovarianceMatrixInTangentSpace(blocks, cov.data());
    if (have_cov) {
      res.covariance = cov * (res.noise_sigma_px * res.noise_sigma_px);
      break;
    }
  }
  if (!have_cov)
    res.notes.push_back(
        "the covariance could not be computed (rank-deficient problem): the data do not determine "
        "every parameter");
}

// Camera c's model, intrinsics stddev and per-view RMS.
CameraResult camera_result(const CalibrationResult& res, const CameraInput& cam, size_t c,
                           const std::vector<double>& intr, const Lens& lens) {
  const size_t n_frames = cam.frames.size();
  CameraResult cr;
  rig::CameraModel& m = cr.model;
  m.fx = intr[0], m.fy = intr[1], m.cx = intr[2], m.cy = intr[3];
  m.distortion_model =
      lens.radtan ? rig::DistortionModel::radtan : rig::DistortionModel::equidistant;
  m.distortion_coeffs.assign(intr.begin() + 4, intr.end());
  m.width = cam.width;
  m.height = cam.height;
  const int at = res.intrinsics_covariance_index[c];
  for (int i = at; i < at + lens.intrinsics_size(); ++i)
    cr.stddev.push_back(std::sqrt(std::max(0.0, res.covariance(i, i))));
  std::vector<double> sse_f(n_frames, 0.0);
  std::vector<int> n_f(n_frames, 0);
  for (const CornerResidual& r : res.residuals) {
    if (r.camera != static_cast<int>(c) || r.outlier) continue;
    sse_f[r.frame] += r.residual.squaredNorm();
    ++n_f[r.frame];
    ++cr.n_corners;
  }
  for (size_t f = 0; f < n_frames; ++f) {
    cr.view_rms.push_back(n_f[f] ? std::sqrt(sse_f[f] / n_f[f]) : NAN);
    cr.n_views += n_f[f] > 0;
  }
  return cr;
}

// T_cam_cam0 of camera c and its 1-sigma in deg and m (camera 0: identity, 0).
void add_camera_pose(CalibrationResult& res, size_t c, const std::vector<Pose>& cam_pose) {
  res.T_cam_cam0.push_back(c == 0 ? SE3() : cam_pose[c].se3());
  if (c == 0) {
    res.rotation_stddev_deg.emplace_back(0, 0, 0);
    res.translation_stddev_m.emplace_back(0, 0, 0);
  } else {
    const int base = res.pose_covariance_index[c];
    Eigen::Vector3d r, t;
    for (int i = 0; i < 3; ++i) {
      // Ceres' quaternion tangent: q + d = [cos|d|, sin|d| d/|d|] q, a rotation of 2|d|.
      r[i] = 2.0 * std::sqrt(std::max(0.0, res.covariance(base + i, base + i))) * 180.0 / M_PI;
      t[i] = std::sqrt(std::max(0.0, res.covariance(base + 3 + i, base + 3 + i)));
    }
    res.rotation_stddev_deg.push_back(r);
    res.translation_stddev_m.push_back(t);
  }
}

}  // namespace

CalibrationResult calibrate(const Target& target, const std::vector<CameraInput>& cams,
                            const CalibrationOptions& opt) {
  check_frames_pair_up(cams);
  const Lenses lenses = lenses_of(opt, cams.size());
  const BoardPoints object = board_points(target);

  // ---- initialization, per camera: OpenCV's calibration gives intrinsics and board poses ----
  Parameters x;
  std::vector<std::vector<std::optional<SE3>>> T_c_board(cams.size());
  for (size_t c = 0; c < cams.size(); ++c)
    x.intr.push_back(initial_intrinsics(cams[c], object.p, lenses[c], opt.min_views, T_c_board[c]));
  x.cam_pose = camera_poses(cams, T_c_board);
  x.board = board_poses(T_c_board, x.cam_pose);
  x.solve_warp = opt.board_warp;

  // ---- the joint problem, with outlier rejection ----
  CalibrationResult res;
  res.residuals = corner_residuals(cams, x.board);
  reject_outliers(res.residuals, object, lenses, opt, x);
  // Final: plain least squares on the inliers, kept for the covariance.
  ceres::Problem problem;
  solve(res.residuals, object, lenses, false, opt.huber_px, x, problem);
  update_residuals(res.residuals, object, lenses, x);
  fit_statistics(res, x);
  add_covariance(res, problem, x);
  if (x.solve_warp) {
    res.board_warp_m = x.warp;
    const int i = res.warp_covariance_index;
    res.board_warp_stddev_m = res.covariance.diagonal().segment<2>(i).cwiseMax(0.0).cwiseSqrt();
  }

  for (size_t c = 0; c < cams.size(); ++c) {
    res.cameras.push_back(camera_result(res, cams[c], c, x.intr[c], lenses[c]));
    add_camera_pose(res, c, x.cam_pose);
  }
  for (const auto& b : x.board)
    res.T_cam0_board.push_back(b ? std::optional<SE3>(b->se3()) : std::nullopt);
  return res;
}

FitAtStored fit_at_stored(const Target& target, const std::vector<CameraInput>& cams,
                          const std::vector<rig::CameraModel>& models,
                          const std::vector<SE3>& T_cam_cam0, const CalibrationOptions& opt) {
  check_frames_pair_up(cams);
  if (models.size() != cams.size() || T_cam_cam0.size() != cams.size())
    throw std::invalid_argument("fit_at_stored: one model and one pose a camera");
  Lenses lenses;
  for (const rig::CameraModel& m : models) {
    const bool radtan = m.distortion_model == rig::DistortionModel::radtan;
    const int n = static_cast<int>(m.distortion_coeffs.size());
    const bool known = radtan ? n == 4 || n == 5
                              : m.distortion_model == rig::DistortionModel::equidistant && n == 4;
    if (!known)
      throw Error(fmt::format("a stored camera's lens ({}, {} coefficients) cannot be fitted",
                              rig::to_string(m.distortion_model), n));
    lenses.push_back({radtan, n});
  }
  const BoardPoints object = board_points(target);
  // Each detected board's pose in each camera from its undistorted corners (PnP), as the start.
  std::vector<std::vector<std::optional<SE3>>> T_c_board(cams.size());
  for (size_t c = 0; c < cams.size(); ++c) {
    T_c_board[c].assign(cams[c].frames.size(), std::nullopt);
    for (size_t f = 0; f < cams[c].frames.size(); ++f) {
      const Detection& d = cams[c].frames[f];
      if (!d.found || d.pixels.size() < 6) continue;
      std::vector<cv::Point3d> obj;
      std::vector<cv::Point2d> img;
      for (size_t i = 0; i < d.pixels.size(); ++i) {
        const Eigen::Vector3d& p = object.p[d.point_ids[i]];
        const Eigen::Vector2d xn = unproject(models[c], d.pixels[i]);
        obj.emplace_back(p.x(), p.y(), p.z());
        img.emplace_back(xn.x(), xn.y());
      }
      cv::Mat rvec, tvec;
      if (cv::solvePnP(obj, img, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rvec, tvec))
        T_c_board[c][f] = from_rvec_tvec(rvec, tvec);
    }
  }
  Parameters x;
  for (const rig::CameraModel& m : models) x.intr.push_back(intrinsics_vector(m));
  x.cam_pose.resize(cams.size());
  for (size_t c = 1; c < cams.size(); ++c) x.cam_pose[c] = Pose::from(T_cam_cam0[c]);
  x.board = board_poses(T_c_board, x.cam_pose);
  x.hold_cameras = true;
  x.solve_warp = opt.board_warp;
  CalibrationResult res;
  res.residuals = corner_residuals(cams, x.board);
  if (res.residuals.empty()) throw Error("no detected board to fit the stored cameras to");
  reject_outliers(res.residuals, object, lenses, opt, x);
  ceres::Problem problem;
  solve(res.residuals, object, lenses, false, opt.huber_px, x, problem);
  update_residuals(res.residuals, object, lenses, x);
  FitAtStored out;
  double sse = 0;
  std::vector<double> camera_sse(cams.size(), 0.0);
  std::vector<size_t> camera_n(cams.size(), 0);
  for (const CornerResidual& cr : res.residuals) {
    if (cr.outlier) {
      ++out.outliers;
      continue;
    }
    sse += cr.residual.squaredNorm();
    camera_sse[cr.camera] += cr.residual.squaredNorm();
    ++camera_n[cr.camera], ++out.corners;
  }
  for (const auto& b : x.board) out.views += b.has_value();
  out.rms_2d_px = std::sqrt(sse / std::max<size_t>(1, out.corners));
  for (size_t c = 0; c < cams.size(); ++c)
    out.camera_rms_2d_px.push_back(std::sqrt(camera_sse[c] / std::max<size_t>(1, camera_n[c])));
  return out;
}

}  // namespace rigcal::camera
