#pragma once
// Calibration targets (doc/targets.md): checkerboards and Kalibr AprilGrids, their object points in
// the board frame, their physical outline and their printed pattern (for the simulator and the
// printable PDF).
//
// Board frame: origin at the first corner (checkerboard: the first inner corner; AprilGrid: the
// bottom-left corner of tag 0), x along the columns, y along the rows, z = x × y; the pattern lies
// in z = 0. Checkerboard rows run downwards as printed; AprilGrid rows run upwards (Kalibr).
#include <string>
#include <vector>

#include "rigcal/core/se3.h"

namespace rigcal::camera {

enum class TargetType { checkerboard, aprilgrid };

struct Target {
  std::string name;
  TargetType type = TargetType::checkerboard;
  int cols = 0, rows = 0;    // checkerboard: inner corners; aprilgrid: tags
  double square = 0;         // checkerboard: side of a square, m
  double tag_size = 0;       // aprilgrid: side of a tag's black square (2-bit border included), m
  double tag_spacing = 0;    // aprilgrid: gap between tags / tag_size (Kalibr's tagSpacing)
  double margin = -1;        // white border around the pattern, m (< 0: one square, or one gap)
  double thickness = 0.005;  // of the physical board, m
};

// What a target may be: boards people print and hold (the largest in use are about 2 m), with
// room to spare; a target over these is a typo or a hostile file, refused before any drawing.
inline constexpr int kMaxTargetCorners = 200;      // cols and rows, each
inline constexpr double kMaxTargetSide = 10.0;     // m, the board's outline, margin included
inline constexpr double kMaxBoardThickness = 0.2;  // m

// Throws rigcal::Error naming the bad field.
void validate(const Target& target);

// Object points (z = 0) in the order detections are reported:
//   checkerboard: inner corners row by row, point (i, j) at (i * square, j * square);
//   aprilgrid: Kalibr's grid of 2*cols x 2*rows tag corners, row by row from the bottom-left;
//     point (m, n) belongs to tag (n / 2) * cols + m / 2.
std::vector<Eigen::Vector3d> object_points(const Target& target);

// A board that is not flat, as mrcal models it (its `calobject_warp`): along x and along y a
// parabola that is zero at the first and the last object point and `warp_m` high at the middle,
// added to z: z = warp_m.x() * 4 xr (1 - xr) + warp_m.y() * 4 yr (1 - yr), with xr = x / (the
// object points' extent in x), yr likewise. The two parabolas' values at board point (x, y):
Eigen::Vector2d board_warp_basis(const Target& target, double x, double y);
// The same with the object points' extent (x, y) given: 1 / board_points_extent(target).
Eigen::Vector2d board_points_extent(const Target& target);
inline Eigen::Vector2d board_warp_basis(const Eigen::Vector2d& inverse_extent, double x, double y) {
  const double xr = x * inverse_extent.x(), yr = y * inverse_extent.y();
  return {4 * xr * (1 - xr), 4 * yr * (1 - yr)};
}
// Point p of the flat board moved onto the warped one.
inline Eigen::Vector3d warped(const Target& target, const Eigen::Vector3d& p,
                              const Eigen::Vector2d& warp_m) {
  return p + Eigen::Vector3d(0, 0, warp_m.dot(board_warp_basis(target, p.x(), p.y())));
}

// The physical board in the board frame: x_min..x_max, y_min..y_max (pattern plus margin).
struct Outline {
  double x_min = 0, x_max = 0, y_min = 0, y_max = 0;
  double width() const { return x_max - x_min; }
  double height() const { return y_max - y_min; }
};
Outline outline(const Target& target);

// The printed pattern at board point (x, y): 0 black, 1 white (the margin is white). Outside the
// outline the result is meaningless; callers test the outline first.
class Pattern {
 public:
  explicit Pattern(const Target& target);
  double albedo(double x, double y) const;
  // The axis-aligned cell of the pattern's finest grid holding (x, y) (squares; an AprilGrid's
  // gaps and its tags' 10 x 10 cells), as two integers: albedo is constant within a cell, so
  // points of one cell share it, and so does everything in their convex hull.
  std::pair<long, long> cell(double x, double y) const;

 private:
  Target target_;
  // AprilGrid: per tag, the 6 x 6 data bits as printed (row 0 at the top), 1 white.
  std::vector<std::array<uint8_t, 36>> tag_bits_;
};

}  // namespace rigcal::camera
