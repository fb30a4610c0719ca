#pragma once
// A saddle point (a checkerboard corner, or where an AprilGrid tag meets its corner square)
// located to a fraction of a pixel by fitting a model of the grey values around it: two straight
// edges through the corner, each blurred by a Gaussian, the image a + b erf(d1 / (sqrt(2) s))
// erf(d2 / (sqrt(2) s)) with d1, d2 the signed distances of a pixel's centre to the two edges
// (exact for perpendicular edges and a Gaussian blur; the pixel's own area is a box of variance
// 1/12 px^2 that s absorbs). Seven parameters (the corner, both edges' directions, s, a, b) by
// Gauss-Newton with Levenberg-Marquardt damping over the pixels of a disc.
//
// The disc is a compromise: a larger one averages more noise, but the edges of a real board are
// not straight (lens distortion, a bent board curve them), and straight edges fitted to edges of
// curvature kappa move the corner by about kappa r^2 / 8, the same way in every view. Fitting the
// curvature too (two more parameters) removes that bias but costs more in noise than a small
// disc does (doc/cameras.md): detect.h's discs are at most 4 px.
//
// Why not cv::cornerSubPix alone: it solves for the point where the image gradients are
// orthogonal to the directions from it, over pixel centres, which pulls corners towards pixel
// centres (pixel locking: an error periodic in the corner's sub-pixel position, about 0.025 px
// amplitude on rendered boards, doc/cameras.md). A model fitted to the grey values has no
// preferred phase where the model matches the image.
#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace rigcal::camera {

struct SaddleFit {
  bool ok = false;         // converged, the corner within `max_shift_px` of the start
  Eigen::Vector2d corner;  // px, pixel centres at integer coordinates
  double blur_px = 0;      // s: the edges' Gaussian width, pixel area included
  double contrast_dn = 0;  // |b|
};

// `gray` 8-bit single channel; `start` within about a pixel of the corner; `radius_px` the disc
// in which the image is the saddle alone (no other edge within it: for an AprilGrid, less than
// the tag's 2-bit border). A disc leaving the image, too few pixels or a fit moving more than
// `max_shift_px` from `start` give ok = false.
// Bilinear intensity of an 8-bit image at a sub-pixel position (pixel centres at integer
// coordinates); the position and its right and lower neighbours must be inside the image.
double bilinear(const cv::Mat& gray, double x, double y);

SaddleFit fit_saddle(const cv::Mat& gray, const Eigen::Vector2d& start, double radius_px,
                     double max_shift_px = 1.0);

}  // namespace rigcal::camera
