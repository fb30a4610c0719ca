#pragma once
// A calibrated stereo pair rectified: both cameras turned to one orientation whose x axis is the
// baseline (Fusiello's construction, the rotation cv::stereoRectify's Bouguet variant also
// reaches up to a small roll), each image resampled through its own lens into one shared
// pinhole. After it, a scene point lies on the same image row in both cameras: the rows of the
// same board corner in the two rectified images differ by the corner noise alone when the
// intrinsics and the stereo extrinsic are right, so their difference is a check of the
// calibration a person can see (the rectified pair with its epipolar lines) and read (the RMS).
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "rigcal/camera/detect.h"
#include "rigcal/core/se3.h"
#include "rigcal/rig/rig.h"

namespace rigcal::camera {

struct Rectification {
  // The rectified frame's orientation from each camera: p_rect = R_rect_cam p_cam.
  Eigen::Matrix3d R_rect_l = Eigen::Matrix3d::Identity(), R_rect_r = Eigen::Matrix3d::Identity();
  // The shared pinhole (no distortion), of the left camera's image size.
  double f_px = 0, cx_px = 0, cy_px = 0;
  int width = 0, height = 0;
};

// From the two lenses and T_r_l (the right camera's pose from the left's). The shared focal
// length is the smaller of the four (no pixel is magnified), the principal point the centre.
Rectification rectify(const rig::CameraModel& left, const rig::CameraModel& right,
                      const SE3& T_r_l);

// A pixel of `camera` (rotated by R_rect_cam) in the rectified image.
Eigen::Vector2d rectified_pixel(const Rectification& rect, const rig::CameraModel& camera,
                                const Eigen::Matrix3d& R_rect_cam, const Eigen::Vector2d& pixel);

// The rows of the corners both cameras saw in one view, rectified: right's row less left's, px.
std::vector<double> row_differences(const Rectification& rect, const rig::CameraModel& left,
                                    const rig::CameraModel& right, const Detection& in_left,
                                    const Detection& in_right);

// The two images rectified side by side (left, then right) with a horizontal line every
// `line_every_px` rows across both (the epipolar lines) and the view's corners circled, in
// colour: a person sees each corner on the same line in both halves.
cv::Mat rectified_pair_png(const Rectification& rect, const rig::CameraModel& left,
                           const rig::CameraModel& right, const cv::Mat& gray_left,
                           const cv::Mat& gray_right, const Detection& in_left,
                           const Detection& in_right, int line_every_px);

}  // namespace rigcal::camera
