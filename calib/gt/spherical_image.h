#pragma once
// A scan as a spherical image (doc/ground-truth.md, the photometric term of the bundle
// adjustment): a point p in the sensor frame falls at column u = fx atan2(y, x) + cx and row
// v = fy atan2(z, sqrt(x^2 + y^2)) + cy, the formulation of Di Giammarino et al. (MD-SLAM, RA-L
// 2023); the pixel holds its range |p| and intensity (the nearest point's, where several fall in
// one pixel). Rows are beams (row 0 the top one), columns the azimuth over one turn.
#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "rigcal/core/scan.h"

namespace rigcal::gt {

struct SphericalProjection {
  int rows = 0, cols = 0;  // 0: no projection (a scan without beams)
  double fx = 0, cx = 0, fy = 0, cy = 0;

  template <class T>
  void project(const Eigen::Matrix<T, 3, 1>& p, T* u, T* v) const {
    using std::atan2, std::sqrt;
    *u = T(fx) * atan2(p.y(), p.x()) + T(cx);
    *v = T(fy) * atan2(p.z(), sqrt(p.x() * p.x() + p.y() * p.y())) + T(cy);
  }
};

// The projection of a scan's sensor: rows the beams (the highest ring + 1), columns the points of
// its fullest beam, the rows' elevations the line through the mean elevations of the beams'
// points (beams evenly spaced in elevation, as Ouster's are to within a few hundredths of a
// degree). No projection when fewer than 2 beams have points.
SphericalProjection spherical_projection(const Scan& scan);

struct SphericalImage {
  SphericalProjection projection;
  std::vector<double> range_m, intensity;  // rows x cols, row-major; range 0: no point there
};

// The points (in the sensor frame of the image) and their intensities projected to the nearest
// pixel.
SphericalImage spherical_image(const std::vector<Eigen::Vector3d>& p_sensor,
                               const std::vector<float>& intensity,
                               const SphericalProjection& projection);

}  // namespace rigcal::gt
