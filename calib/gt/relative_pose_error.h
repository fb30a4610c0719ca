#pragma once
// The pose graph's odometry term (doc/ground-truth.md): the scan matcher's relative motion
// between two consecutive scan poses against the motion the poses imply, weighted by the step's
// information. Poses as Ceres' pose_graph_3d keeps them: an Eigen quaternion (x y z w) and a
// translation, T_enu_lidar.
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rigcal::gt {

struct RelativePoseError {
  Eigen::Quaterniond q_prev_cur_measured;
  Eigen::Vector3d t_prev_cur_measured;
  // U with U' U the inverse of the step's covariance (rigcal's tangent: the measured motion is
  // perturbed(true motion, e), rotation first).
  Eigen::Matrix<double, 6, 6> sqrt_information;

  template <class T>
  bool operator()(const T* q_enu_prev, const T* t_enu_prev, const T* q_enu_cur, const T* t_enu_cur,
                  T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_a(q_enu_prev), q_b(q_enu_cur);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_a(t_enu_prev), t_b(t_enu_cur);
    const Eigen::Quaternion<T> q_prev_enu = q_a.conjugate();
    const Eigen::Quaternion<T> q_prev_cur = q_prev_enu * q_b;
    const Eigen::Matrix<T, 3, 1> t_prev_cur = q_prev_enu * (t_b - t_a);
    // e: the measured motion relative to the poses' (R_measured = exp(e_rot) R, t_measured = t +
    // e_t).
    const Eigen::Quaternion<T> q_e = q_prev_cur_measured.cast<T>() * q_prev_cur.conjugate();
    const T q_e_wxyz[4] = {q_e.w(), q_e.x(), q_e.y(), q_e.z()};
    Eigen::Matrix<T, 6, 1> e;
    ceres::QuaternionToAngleAxis(q_e_wxyz, e.data());
    e.template tail<3>() = t_prev_cur_measured.cast<T>() - t_prev_cur;
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r = sqrt_information.cast<T>() * e;
    return true;
  }
};

// The same term on the bundle adjustment's knots (a quaternion x y z w, then the translation, in
// one block): a window's motion between two of its poses against the odometry's (keyframes).
struct KnotMotionError {
  RelativePoseError error;
  template <class T>
  bool operator()(const T* knot_prev, const T* knot_cur, T* residual) const {
    return error(knot_prev, knot_prev + 4, knot_cur, knot_cur + 4, residual);
  }
};

}  // namespace rigcal::gt
