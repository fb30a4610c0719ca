#pragma once
// The bundle adjustment's geometric term (doc/ground-truth.md): a scan's point, moved by the
// scan's pose into the map, against the plane of its patch, over the points' noise. Poses as the
// pose graph keeps them: an Eigen quaternion (x y z w) and a translation, T_world_lidar; the
// plane estimated with them: its unit normal n and its offset d from an anchor point c (the
// patch's centroid when it was found), the plane {x : n . (x - c) = d}.
//
// PointToPlaneError defines the residual; PlanePointsCost evaluates it for several points with
// its Jacobians written out (as SweepPlanePointsCost, checked against the automatic ones in the
// tests).
#include <ceres/cost_function.h>
#include <ceres/manifold.h>
#include <ceres/product_manifold.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

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

// A knot of the adjustment as one parameter block of 7: T_world_lidar's Eigen quaternion (x y z
// w), then its translation; its manifold KnotManifold (tangent: half the world-frame rotation
// vector, then the translation).
using KnotManifold =
    ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>>;

// The points of one scan that lie on one plane, all at one knot (PointToPlaneError each, one
// residual a point): parameter blocks the knot (7) and the plane (n then d, 4). One block for
// them all keeps the solver's per-block work to one a scan and plane.
class PlanePointsCost final : public ceres::CostFunction {
 public:
  // `huber`: each point's residual (in sigmas) through Huber's loss at that scale (0: none),
  // folded into the residual so that the block's cost is the sum of the points' losses.
  PlanePointsCost(std::vector<Eigen::Vector3d> p_lidar, const Eigen::Vector3d& c_world,
                  double inv_sigma, double huber = 0);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::vector<Eigen::Vector3d> p_lidar_;
  Eigen::Vector3d c_world_;
  double inv_sigma_, huber_;
};

}  // namespace rigcal::gt
