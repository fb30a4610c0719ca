#pragma once
// The bundle adjustment's geometric term (doc/ground-truth.md): a scan's point, moved by the
// scan's pose into the map, against the plane of its patch, over the points' noise. Poses as the
// pose graph keeps them: an Eigen quaternion (x y z w) and a translation, T_world_lidar; the
// plane estimated with them: its unit normal n and its offset d from an anchor point c (the
// patch's centroid when it was found), the plane {x : n . (x - c) = d}.
//
// PointToPlaneError defines the residual; PointToPlaneCost evaluates it with its Jacobians
// written out (as SweepPointToPlaneCost, checked against the automatic ones in the tests).
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rigcal::gt {

struct PointToPlaneError {
  Eigen::Vector3d p_lidar;  // the point in its scan's frame (deskewed to the scan's stamp)
  Eigen::Vector3d c_world;  // the plane's anchor
  double inv_sigma = 1.0;   // 1 / the point's noise along the normal, 1/m

  template <class T>
  // plane: n (unit), then d.
  bool operator()(const T* q_world_lidar, const T* t_world_lidar, const T* plane,
                  T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_world_lidar);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(t_world_lidar), n(plane);
    const Eigen::Matrix<T, 3, 1> p_world = q * p_lidar.cast<T>() + t;
    residual[0] = T(inv_sigma) * (n.dot(p_world - c_world.cast<T>()) - plane[3]);
    return true;
  }
};

// Parameter blocks: q_world_lidar (EigenQuaternionManifold), t_world_lidar, plane (n then d).
class PointToPlaneCost final : public ceres::SizedCostFunction<1, 4, 3, 4> {
 public:
  explicit PointToPlaneCost(const PointToPlaneError& e) : e_(e) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  PointToPlaneError e_;
};

}  // namespace rigcal::gt
