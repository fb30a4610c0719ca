#pragma once
// Simulated images of a calibration target (doc/simulator.md): varied board poses seen by one or
// two cameras, rendered through the true lens model with area integration, optical blur,
// vignetting, shot and read noise, and optionally an RGGB Bayer mosaic.
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include "rigcal/camera/target.h"
#include "rigcal/rig/rig.h"

namespace rigcal::sim {

struct ImageConfig {
  int supersample = 5;           // S x S samples a pixel: the pixel's area integrated
  double blur_sigma_px = 0.6;    // Gaussian optical blur
  double black_dn = 25.0;        // printed black under the light, digital numbers (8 bit)
  double white_dn = 215.0;       // printed white
  double background_dn = 110.0;  // what lies behind the board
  double gain_dn_per_e = 0.25;   // shot noise: variance = gain * signal (DN^2)
  double read_noise_dn = 1.5;    // read noise, std (DN)
  double vignetting = 0.25;      // fall-off at the image corners: 1 - v (r / r_corner)^2
  bool bayer = false;            // RGGB mosaic, like the raw VBR images
  double gain_r = 0.55, gain_g = 1.0, gain_b = 0.75;  // colour response in the mosaic
};

struct BoardPoseConfig {
  int views = 40;
  double min_fill = 0.10, max_fill = 0.80;  // board's larger side, fraction of the image width
  double max_tilt_deg = 50.0;               // board normal away from the optical axis
  double max_roll_deg = 30.0;               // board rotation about the optical axis
  double margin_px = 8.0;                   // every board corner this far inside the image
  double min_square_px = 8.0;               // the smallest distance between neighbouring points
};

// Board poses T_camL_board such that the whole board is seen by the left camera and, when
// `right` is given, by the right one (T_right_left maps left-camera points into the right one).
// Image positions cycle over a 3 x 3 grid so that the corners of the image are covered.
// Throws rigcal::Error when no valid pose is found.
std::vector<SE3> board_poses(const rig::CameraModel& left, const rig::CameraModel* right,
                             const SE3& T_right_left, const camera::Target& target,
                             const BoardPoseConfig& config, std::mt19937_64& rng);

// Per-pixel rays of a camera: the normalized coordinates of each pixel centre and their
// derivative with respect to the pixel position (for sub-pixel samples).
struct PixelRays {
  int width = 0, height = 0;
  std::vector<Eigen::Vector2d> xn;
  std::vector<Eigen::Matrix2d> dxn_dpixel;
};
PixelRays pixel_rays(const rig::CameraModel& camera);

// One 8-bit image (CV_8UC1; a raw RGGB mosaic with config.bayer) of the board at T_cam_board,
// warped by board_warp_m (camera/target.h; zero: flat).
cv::Mat render_board(const PixelRays& rays, const camera::Target& target,
                     const camera::Pattern& pattern, const SE3& T_cam_board,
                     const ImageConfig& config, std::mt19937_64& rng,
                     const Eigen::Vector2d& board_warp_m = Eigen::Vector2d::Zero());

// The true pixel positions of the target's object points; nullopt entries behind the camera.
std::vector<Eigen::Vector2d> project_points(const rig::CameraModel& camera, const SE3& T_cam_board,
                                            const std::vector<Eigen::Vector3d>& points_board);

}  // namespace rigcal::sim
