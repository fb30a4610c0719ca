#include "rigcal/camera/uncertainty.h"

#include <Eigen/Eigenvalues>

#include "rigcal/camera/calibrate.h"
#include "rigcal/camera/lens.h"

namespace rigcal::camera {
namespace {

rig::CameraModel with(const rig::CameraModel& m, const std::vector<double>& k) {
  rig::CameraModel out = m;
  out.fx = k[0], out.fy = k[1], out.cx = k[2], out.cy = k[3];
  out.distortion_coeffs.assign(k.begin() + 4, k.end());
  return out;
}

}  // namespace

UncertaintyMap projection_uncertainty(const rig::CameraModel& model, const Eigen::MatrixXd& cov,
                                      double distance_m, int cell_px) {
  UncertaintyMap map;
  map.cell_px = cell_px;
  map.cols = (model.width + cell_px - 1) / cell_px;
  map.rows = (model.height + cell_px - 1) / cell_px;
  const std::vector<double> k0 = intrinsics_vector(model);
  const int n = static_cast<int>(k0.size());
  double sum = 0.0;
  for (int r = 0; r < map.rows; ++r) {
    for (int c = 0; c < map.cols; ++c) {
      const Eigen::Vector2d q((c + 0.5) * cell_px, (r + 0.5) * cell_px);
      const Eigen::Vector2d xn = unproject(model, q);
      const Eigen::Vector3d p = distance_m * Eigen::Vector3d(xn.x(), xn.y(), 1.0).normalized();
      Eigen::MatrixXd J(2, n);
      for (int i = 0; i < n; ++i) {
        std::vector<double> kp = k0, km = k0;
        const double h = 1e-6 * std::max(1.0, std::abs(k0[i]));
        kp[i] += h;
        km[i] -= h;
        J.col(i) = (*project(with(model, kp), p) - *project(with(model, km), p)) / (2 * h);
      }
      const Eigen::Matrix2d S = J * cov * J.transpose();
      const double sigma = std::sqrt(std::max(
          0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(S).eigenvalues().maxCoeff()));
      map.sigma_px.push_back(sigma);
      sum += sigma;
      map.max_px = std::max(map.max_px, sigma);
    }
  }
  map.mean_px = sum / map.sigma_px.size();
  map.centre_px = map.sigma_px[(map.rows / 2) * map.cols + map.cols / 2];
  return map;
}

}  // namespace rigcal::camera
