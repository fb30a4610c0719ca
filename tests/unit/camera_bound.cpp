#include "camera_bound.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <opencv2/calib3d.hpp>
#include <utility>

#include "rigcal/core/error.h"

namespace rigcal::camera {
namespace {

// A rigid transform as the bound perturbs it: R' = exp(d_rot) R (left, as the error is defined),
// t' = t + d_t. Eigen's angle-axis, not rigcal's SO(3) code.
struct RigidTransform {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  RigidTransform perturbed(int i, double h) const {
    RigidTransform out = *this;
    if (i < 3) {
      out.R = Eigen::AngleAxisd(h, Eigen::Vector3d::Unit(i)).toRotationMatrix() * R;
    } else {
      out.t[i - 3] += h;
    }
    return out;
  }
};

// OpenCV's projection of points in the camera frame, intrinsics [fx fy cx cy k...].
std::vector<Eigen::Vector2d> opencv_project(rig::DistortionModel model,
                                            const std::vector<double>& intrinsics,
                                            const std::vector<Eigen::Vector3d>& p_cam) {
  std::vector<cv::Point3d> pts;
  pts.reserve(p_cam.size());
  for (const Eigen::Vector3d& p : p_cam) pts.emplace_back(p.x(), p.y(), p.z());
  const cv::Matx33d K(intrinsics[0], 0, intrinsics[2], 0, intrinsics[1], intrinsics[3], 0, 0, 1);
  const std::vector<double> D(intrinsics.begin() + 4, intrinsics.end());
  const cv::Vec3d zero(0, 0, 0);
  std::vector<cv::Point2d> px;
  if (model == rig::DistortionModel::equidistant) {
    if (D.size() != 4) throw Error("the bound: equidistant needs k1..k4");
    cv::fisheye::projectPoints(pts, px, zero, zero, K, cv::Vec4d(D[0], D[1], D[2], D[3]));
  } else {
    cv::projectPoints(pts, zero, zero, K, D, px);
  }
  std::vector<Eigen::Vector2d> out;
  out.reserve(px.size());
  for (const cv::Point2d& q : px) out.emplace_back(q.x, q.y);
  return out;
}

// The corners of one camera in one frame, projected with the given parameters.
std::vector<Eigen::Vector2d> project_group(rig::DistortionModel model,
                                           const std::vector<double>& intrinsics,
                                           const RigidTransform& T_cam_cam0,
                                           const RigidTransform& T_cam0_board,
                                           const std::vector<Eigen::Vector3d>& p_board) {
  std::vector<Eigen::Vector3d> p_cam;
  p_cam.reserve(p_board.size());
  for (const Eigen::Vector3d& p : p_board)
    p_cam.push_back(T_cam_cam0.R * (T_cam0_board.R * p + T_cam0_board.t) + T_cam_cam0.t);
  return opencv_project(model, intrinsics, p_cam);
}

}  // namespace

CramerRaoBound cramer_rao_bound(const std::vector<rig::CameraModel>& cameras,
                                const std::vector<SE3>& T_cam_cam0,
                                const std::vector<SE3>& T_cam0_board,
                                const std::vector<Eigen::Vector3d>& points_board,
                                const std::vector<CornerResidual>& corners) {
  const size_t n_cams = cameras.size();
  if (n_cams == 0 || T_cam_cam0.size() != n_cams)
    throw Error("the bound: one T_cam_cam0 a camera is needed");
  const rig::DistortionModel model = cameras[0].distortion_model;
  const int NK = 4 + static_cast<int>(cameras[0].distortion_coeffs.size());
  std::vector<std::vector<double>> intrinsics;
  for (const rig::CameraModel& c : cameras) {
    if (c.distortion_model != model || 4 + static_cast<int>(c.distortion_coeffs.size()) != NK)
      throw Error("the bound: the cameras must share one lens model");
    std::vector<double> k = {c.fx, c.fy, c.cx, c.cy};
    k.insert(k.end(), c.distortion_coeffs.begin(), c.distortion_coeffs.end());
    intrinsics.push_back(k);
  }
  std::vector<RigidTransform> cam(n_cams), board(T_cam0_board.size());
  for (size_t c = 0; c < n_cams; ++c) cam[c] = {T_cam_cam0[c].R, T_cam_cam0[c].t};
  for (size_t f = 0; f < board.size(); ++f) board[f] = {T_cam0_board[f].R, T_cam0_board[f].t};

  // The inlier corners by camera and frame; a board pose for every frame that has one.
  std::map<std::pair<int, int>, std::vector<size_t>> groups;  // (camera, frame) -> corner rows
  std::vector<const CornerResidual*> used;
  for (const CornerResidual& c : corners) {
    if (c.outlier) continue;
    if (c.camera < 0 || c.camera >= static_cast<int>(n_cams) || c.frame < 0 ||
        c.frame >= static_cast<int>(board.size()) || c.point < 0 ||
        c.point >= static_cast<int>(points_board.size()))
      throw Error("the bound: a corner's camera, frame or point is out of range");
    groups[{c.camera, c.frame}].push_back(used.size());
    used.push_back(&c);
  }
  const int K = static_cast<int>(n_cams) * NK + 6 * (static_cast<int>(n_cams) - 1);
  std::vector<int> board_column(board.size(), -1);
  int P = K;
  for (const auto& [key, rows] : groups) {
    if (board_column[key.second] < 0) {
      board_column[key.second] = P;
      P += 6;
    }
  }
  const Eigen::Index M = 2 * static_cast<Eigen::Index>(used.size());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(M, P);
  Eigen::VectorXd r0(M);  // observed - true projection

  // Central differences. The projection is linear in each intrinsic (fx, cx, k1, ... one at a
  // time), so their steps only need to keep round-off small; the poses' steps (1e-6 rad, 1e-6 m)
  // leave a truncation error of ~1e-12 relative.
  constexpr double h_pinhole = 1e-3, h_distortion = 1e-5, h_pose = 1e-6;
  for (const auto& [key, rows] : groups) {
    const auto [c, f] = key;
    std::vector<Eigen::Vector3d> p_board;
    for (size_t k : rows) p_board.push_back(points_board[used[k]->point]);
    const std::vector<Eigen::Vector2d> at_truth =
        project_group(model, intrinsics[c], cam[c], board[f], p_board);
    for (size_t i = 0; i < rows.size(); ++i)
      r0.segment<2>(2 * rows[i]) = used[rows[i]]->observed - at_truth[i];
    const auto fill = [&](int column, double h, const std::vector<Eigen::Vector2d>& plus,
                          const std::vector<Eigen::Vector2d>& minus) {
      for (size_t i = 0; i < rows.size(); ++i)
        J.block<2, 1>(2 * rows[i], column) = (plus[i] - minus[i]) / (2 * h);
    };
    for (int j = 0; j < NK; ++j) {
      const double h = j < 4 ? h_pinhole : h_distortion;
      std::vector<double> plus = intrinsics[c], minus = intrinsics[c];
      plus[j] += h, minus[j] -= h;
      fill(c * NK + j, h, project_group(model, plus, cam[c], board[f], p_board),
           project_group(model, minus, cam[c], board[f], p_board));
    }
    if (c > 0) {
      for (int j = 0; j < 6; ++j) {
        fill(static_cast<int>(n_cams) * NK + 6 * (c - 1) + j, h_pose,
             project_group(model, intrinsics[c], cam[c].perturbed(j, h_pose), board[f], p_board),
             project_group(model, intrinsics[c], cam[c].perturbed(j, -h_pose), board[f], p_board));
      }
    }
    for (int j = 0; j < 6; ++j) {
      fill(board_column[f] + j, h_pose,
           project_group(model, intrinsics[c], cam[c], board[f].perturbed(j, h_pose), p_board),
           project_group(model, intrinsics[c], cam[c], board[f].perturbed(j, -h_pose), p_board));
    }
  }

  CramerRaoBound out;
  out.n_corners = used.size();
  out.n_frames = static_cast<size_t>(P - K) / 6;
  out.n_parameters = static_cast<size_t>(P);
  out.noise_sigma_px = std::sqrt(r0.squaredNorm() / static_cast<double>(M));
  for (Eigen::Index i = 0; i < M; ++i) out.noise_mean_px[i % 2] += r0[i] / (M / 2);
  double z2 = 0, pair_sum = 0;
  size_t n_views = 0, n_pairs = 0;
  for (const auto& [key, rows] : groups) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    std::map<int, size_t> row_of_point;
    for (size_t k : rows) {
      sum += r0.segment<2>(2 * k);
      row_of_point[used[k]->point] = k;
    }
    z2 += sum.squaredNorm() /
          (static_cast<double>(rows.size()) * out.noise_sigma_px * out.noise_sigma_px);
    n_views += 2;
    for (const auto& [point, k] : row_of_point) {
      const auto next = row_of_point.find(point + 1);
      if (next == row_of_point.end() || points_board[point].y() != points_board[point + 1].y())
        continue;
      pair_sum += r0.segment<2>(2 * k).dot(r0.segment<2>(2 * next->second));
      n_pairs += 2;
    }
  }
  out.view_mean_z_rms = std::sqrt(z2 / static_cast<double>(n_views));
  out.neighbour_correlation =
      pair_sum / static_cast<double>(n_pairs) / (out.noise_sigma_px * out.noise_sigma_px);

  // Normal matrix, columns scaled to a unit diagonal (the parameters' units differ by 1e6), its
  // condition from the eigenvalues, its inverse by a dense LDLT.
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(P, P);
  N.selfadjointView<Eigen::Lower>().rankUpdate(J.transpose());
  N = N.selfadjointView<Eigen::Lower>();
  const Eigen::VectorXd d = N.diagonal().cwiseSqrt().cwiseInverse();
  if (!d.allFinite()) throw Error("the bound: a parameter no corner depends on");
  const Eigen::MatrixXd Ns = d.asDiagonal() * N * d.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Ns, Eigen::EigenvaluesOnly);
  out.condition = eig.eigenvalues().maxCoeff() / eig.eigenvalues().minCoeff();
  if (!(eig.eigenvalues().minCoeff() > 0) || !(out.condition < 1e14))
    throw Error(
        fmt::format("the bound: the normal matrix is singular (condition {:.3g})", out.condition));
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(Ns);
  const Eigen::MatrixXd Ns_inv = ldlt.solve(Eigen::MatrixXd::Identity(P, P));
  const Eigen::MatrixXd N_inv = d.asDiagonal() * Ns_inv * d.asDiagonal();
  const Eigen::VectorXd step = N_inv * (J.transpose() * r0);

  // The parameters of interest, rotations in degrees.
  Eigen::VectorXd unit = Eigen::VectorXd::Ones(K);
  const char* intrinsic_names[] = {"fx", "fy", "cx", "cy"};
  const char* radtan_names[] = {"k1", "k2", "p1", "p2", "k3"};
  for (size_t c = 0; c < n_cams; ++c) {
    for (int j = 0; j < NK; ++j) {
      std::string n;
      if (j < 4)
        n = intrinsic_names[j];
      else if (model == rig::DistortionModel::equidistant)
        n = fmt::format("k{}", j - 3);
      else
        n = radtan_names[j - 4];
      out.names.push_back(fmt::format("cam{} {}", c, n));
    }
  }
  for (size_t c = 1; c < n_cams; ++c) {
    for (const char* axis : {"x", "y", "z"})
      out.names.push_back(fmt::format("cam{} rotation {} (deg)", c, axis));
    for (const char* axis : {"x", "y", "z"})
      out.names.push_back(fmt::format("cam{} translation {} (m)", c, axis));
    for (int i = 0; i < 3; ++i)
      unit[static_cast<int>(n_cams) * NK + 6 * (static_cast<int>(c) - 1) + i] = 180.0 / M_PI;
  }
  const double s2 = out.noise_sigma_px * out.noise_sigma_px;
  out.covariance = s2 * unit.asDiagonal() * N_inv.topLeftCorner(K, K) * unit.asDiagonal();
  out.sigma = out.covariance.diagonal().cwiseSqrt();
  out.lsq_error = unit.cwiseProduct(step.head(K));
  return out;
}

}  // namespace rigcal::camera
