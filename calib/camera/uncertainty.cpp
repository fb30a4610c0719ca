#include "rigcal/camera/uncertainty.h"

#include <Eigen/Eigenvalues>

#include "rigcal/camera/calibrate.h"
#include "rigcal/camera/lens.h"
#include "rigcal/core/se3.h"

namespace rigcal::camera {
namespace {

rig::CameraModel with(const rig::CameraModel& m, const std::vector<double>& k) {
  rig::CameraModel out = m;
  out.fx = k[0], out.fy = k[1], out.cx = k[2], out.cy = k[3];
  out.distortion_coeffs.assign(k.begin() + 4, k.end());
  return out;
}

// d project(model with k, p) / d k, by central differences.
Eigen::MatrixXd intrinsics_jacobian(const rig::CameraModel& model, const Eigen::Vector3d& p) {
  const std::vector<double> k0 = intrinsics_vector(model);
  const int n = static_cast<int>(k0.size());
  Eigen::MatrixXd J(2, n);
  for (int i = 0; i < n; ++i) {
    std::vector<double> kp = k0, km = k0;
    const double h = 1e-6 * std::max(1.0, std::abs(k0[i]));
    kp[i] += h;
    km[i] -= h;
    J.col(i) = (*project(with(model, kp), p) - *project(with(model, km), p)) / (2 * h);
  }
  return J;
}

double worst_sigma(const Eigen::Matrix2d& S) {
  return std::sqrt(
      std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(S).eigenvalues().maxCoeff()));
}

UncertaintyMap empty_map(const rig::CameraModel& model, int cell_px) {
  UncertaintyMap map;
  map.cell_px = cell_px;
  map.cols = (model.width + cell_px - 1) / cell_px;
  map.rows = (model.height + cell_px - 1) / cell_px;
  return map;
}

void summarize(UncertaintyMap& map) {
  double sum = 0.0;
  for (double s : map.sigma_px) sum += s, map.max_px = std::max(map.max_px, s);
  map.mean_px = sum / map.sigma_px.size();
  map.centre_px = map.sigma_px[(map.rows / 2) * map.cols + map.cols / 2];
}

// The point at distance_m along the ray of a cell's centre, in the camera frame.
Eigen::Vector3d cell_point(const rig::CameraModel& model, const UncertaintyMap& map, int r, int c,
                           double distance_m) {
  const Eigen::Vector2d q((c + 0.5) * map.cell_px, (r + 0.5) * map.cell_px);
  const Eigen::Vector2d xn = unproject(model, q);
  return distance_m * Eigen::Vector3d(xn.x(), xn.y(), 1.0).normalized();
}

}  // namespace

UncertaintyMap projection_uncertainty(const CalibrationResult& res, int camera, double distance_m,
                                      int cell_px) {
  const rig::CameraModel& model = res.cameras.at(camera).model;
  UncertaintyMap map = empty_map(model, cell_px);
  const int nk = static_cast<int>(res.cameras[camera].stddev.size());
  const Eigen::MatrixXd& cov = res.covariance;
  std::vector<int> frames;
  for (size_t f = 0; f < res.board_covariance_index.size(); ++f) {
    if (res.board_covariance_index[f] >= 0 && res.T_cam0_board[f]) frames.push_back(f);
  }
  const SE3& T_c_0 = res.T_cam_cam0[camera];
  const SE3 T_0_c = T_c_0.inverse();
  for (int r = 0; r < map.rows; ++r) {
    for (int c = 0; c < map.cols; ++c) {
      const Eigen::Vector3d p_c = cell_point(model, map, r, c, distance_m);
      const Eigen::Vector3d p_0 = T_0_c * p_c;
      // dq/dp_c by central differences.
      Eigen::Matrix<double, 2, 3> A;
      for (int i = 0; i < 3; ++i) {
        const double h = 1e-6 * distance_m;
        Eigen::Vector3d dp = Eigen::Vector3d::Zero();
        dp[i] = h;
        A.col(i) = (*project(model, p_c + dp) - *project(model, p_c - dp)) / (2 * h);
      }
      Eigen::MatrixXd J = Eigen::MatrixXd::Zero(2, cov.rows());
      J.block(0, res.intrinsics_covariance_index[camera], 2, nk) = intrinsics_jacobian(model, p_c);
      if (camera > 0) {  // p_c = exp(2 d) R p_0 + t
        const int base = res.pose_covariance_index[camera];
        J.block<2, 3>(0, base) = A * (-2.0 * skew(T_c_0.R * p_0));
        J.block<2, 3>(0, base + 3) = A;
      }
      // p_0 = mean over frames of T_0_board_f p_board_f.
      const Eigen::Matrix<double, 2, 3> B = A * T_c_0.R / static_cast<double>(frames.size());
      for (int f : frames) {
        const SE3& T_0_b = *res.T_cam0_board[f];
        const Eigen::Vector3d p_b = T_0_b.inverse() * p_0;
        const int base = res.board_covariance_index[f];
        J.block<2, 3>(0, base) = B * (-2.0 * skew(T_0_b.R * p_b));
        J.block<2, 3>(0, base + 3) = B;
      }
      map.sigma_px.push_back(worst_sigma(J * cov * J.transpose()));
    }
  }
  summarize(map);
  return map;
}

UncertaintyMap projection_uncertainty_intrinsics_only(const rig::CameraModel& model,
                                                      const Eigen::MatrixXd& cov, double distance_m,
                                                      int cell_px) {
  UncertaintyMap map = empty_map(model, cell_px);
  for (int r = 0; r < map.rows; ++r) {
    for (int c = 0; c < map.cols; ++c) {
      const Eigen::MatrixXd J =
          intrinsics_jacobian(model, cell_point(model, map, r, c, distance_m));
      map.sigma_px.push_back(worst_sigma(J * cov * J.transpose()));
    }
  }
  summarize(map);
  return map;
}

}  // namespace rigcal::camera
