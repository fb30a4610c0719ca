#pragma once
// The bundle adjustment's photometric term (doc/ground-truth.md, eqs. 2-4 of the VBR paper, the
// formulation of MD-SLAM): a point of one scan, placed in the world by its sweep's knots
// (sweep_point_in_world) and moved into the frame of an earlier scan's knot, projected into
// that scan's spherical image (spherical_image.h); the residuals are the image's range and
// intensity there, interpolated (bicubic), minus the point's own, over their noise. The
// reference image is held while a solve runs: it is the earlier scan as the knots placed it
// when the term was built.
#include <ceres/cubic_interpolation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "rigcal/gt/spherical_image.h"
#include "rigcal/gt/sweep_point_to_plane_error.h"

namespace rigcal::gt {

// A reference image ready for interpolation: its range and intensity grids (the image must
// outlive it).
struct ReferenceImage {
  explicit ReferenceImage(const SphericalImage& image)
      : projection(image.projection),
        range_grid(image.range_m.data(), 0, image.projection.rows, 0, image.projection.cols),
        intensity_grid(image.intensity.data(), 0, image.projection.rows, 0, image.projection.cols),
        range(range_grid),
        intensity(intensity_grid) {}
  SphericalProjection projection;
  ceres::Grid2D<double, 1> range_grid, intensity_grid;
  ceres::BiCubicInterpolator<ceres::Grid2D<double, 1>> range, intensity;
};

struct PhotometricError {
  const ReferenceImage* reference = nullptr;
  Eigen::Vector3d p_lidar;  // the point in its sensor frame at its own time
  double fraction = 0;      // its time from knot a, over the time from knot a to knot b
  double intensity = 0;     // the point's own
  double inv_sigma_range = 1, inv_sigma_intensity = 1;  // 1/m, 1/intensity unit

  // Knots as the window's parameter blocks (7 each: the quaternion x y z w, then the
  // translation): the reference scan's, and the two the point lies between.
  template <class T>
  bool operator()(const T* knot_ref, const T* knot_a, const T* knot_b, T* residual) const {
    const Eigen::Matrix<T, 3, 1> p_world =
        sweep_point_in_world(knot_a, knot_a + 4, knot_b, knot_b + 4, p_lidar, fraction);
    const Eigen::Map<const Eigen::Quaternion<T>> q_world_ref(knot_ref);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_world_ref(knot_ref + 4);
    const Eigen::Matrix<T, 3, 1> p_ref = q_world_ref.conjugate() * (p_world - t_world_ref);
    T u, v, range, image_intensity;
    reference->projection.project(p_ref, &u, &v);
    reference->range.Evaluate(v, u, &range);
    reference->intensity.Evaluate(v, u, &image_intensity);
    residual[0] = T(inv_sigma_range) * (range - p_ref.norm());
    residual[1] = T(inv_sigma_intensity) * (image_intensity - T(intensity));
    return true;
  }
};

}  // namespace rigcal::gt
