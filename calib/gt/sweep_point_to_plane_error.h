#pragma once
// The bundle adjustment's geometric term for a point measured during the sweep
// (doc/ground-truth.md): the sensor's motion between two knots (the scan's stamp and the next
// one) taken as the interpolation of the two poses (rotation R_a Exp(f Log(R_a' R_b)),
// translation t_a + f (t_b - t_a), what lidar::motion_fraction does), the point placed by the
// pose at its fraction f of the way and measured against its plane as PointToPlaneError.
//
// SweepPointToPlaneError defines the residual (any scalar type, for automatic differentiation);
// SweepPlanePointsCost evaluates it for the points of a scan on a plane with its Jacobians
// written out (the solver's inner loop: several times faster than the automatic ones, and
// checked against them in the tests).
#include <ceres/cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace rigcal::gt {

// The point p_lidar measured a fraction f of the way from knot a to knot b, placed in the world
// by the interpolated pose (T_world_a, T_world_b as Eigen quaternions x y z w and translations).
template <class T>
Eigen::Matrix<T, 3, 1> sweep_point_in_world(const T* q_world_a, const T* t_world_a,
                                            const T* q_world_b, const T* t_world_b,
                                            const Eigen::Vector3d& p_lidar, double fraction) {
  const Eigen::Map<const Eigen::Quaternion<T>> qa(q_world_a), qb(q_world_b);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> ta(t_world_a), tb(t_world_b);
  const Eigen::Quaternion<T> q_a_b = qa.conjugate() * qb;
  // ceres' order is w x y z; the shorter way round (q and -q are one rotation).
  const T sign = q_a_b.w() < T(0) ? T(-1) : T(1);
  const T wxyz[4] = {sign * q_a_b.w(), sign * q_a_b.x(), sign * q_a_b.y(), sign * q_a_b.z()};
  T phi[3];
  ceres::QuaternionToAngleAxis(wxyz, phi);
  for (T& c : phi) c *= T(fraction);
  const T p[3] = {T(p_lidar.x()), T(p_lidar.y()), T(p_lidar.z())};
  T p_turned[3];
  ceres::AngleAxisRotatePoint(phi, p, p_turned);
  const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_a(p_turned);
  return qa * p_a + ta + T(fraction) * (tb - ta);
}

struct SweepPointToPlaneError {
  Eigen::Vector3d p_lidar;  // the point in the sensor frame at its own time
  double fraction = 0;      // its time from knot a, over the time from knot a to knot b
  Eigen::Vector3d c_world;  // the plane's anchor
  double inv_sigma = 1.0;   // 1 / the point's noise along the normal, 1/m

  template <class T>
  bool operator()(const T* q_world_a, const T* t_world_a, const T* q_world_b, const T* t_world_b,
                  const T* plane, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> n(plane);
    const Eigen::Matrix<T, 3, 1> p_world =
        sweep_point_in_world(q_world_a, t_world_a, q_world_b, t_world_b, p_lidar, fraction);
    residual[0] = T(inv_sigma) * (n.dot(p_world - c_world.cast<T>()) - plane[3]);
    return true;
  }
};

// The points of one scan on one plane measured between knots a and b (SweepPointToPlaneError
// each, one residual a point): parameter blocks knot a, knot b (7 each, KnotManifold) and the
// plane (n then d). The rotations' Jacobians are taken in the world-frame rotation theta of each
// knot (R -> Exp(theta) R): with R_f = R_a Exp(f phi), phi = Log(R_a' R_b) and
// A = f J_r(f phi) J_r(phi)^-1, the point R_f p moves by -[R_f p]x theta_a - R_f [p]x A R_b'
// (theta_b - theta_a). Ceres' quaternion tangent is theta / 2, and its ambient Jacobian is the
// tangent one times the manifold's PlusJacobian transposed (orthonormal columns at a unit q).
class SweepPlanePointsCost final : public ceres::CostFunction {
 public:
  struct Point {
    Eigen::Vector3d p_lidar;
    double fraction = 0;
  };
  // `huber` as PlanePointsCost's.
  SweepPlanePointsCost(std::vector<Point> points, const Eigen::Vector3d& c_world, double inv_sigma,
                       double huber = 0);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::vector<Point> points_;
  Eigen::Vector3d c_world_;
  double inv_sigma_, huber_;
};

}  // namespace rigcal::gt
