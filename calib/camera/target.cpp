#include "rigcal/camera/target.h"

#include <fmt/format.h>

#include <cmath>

#include "rigcal/core/error.h"

extern "C" {
#include <apriltag/tag36h11.h>
}

namespace rigcal::camera {

void validate(const Target& t) {
  auto bad = [&](std::string_view field, std::string_view what) {
    throw Error(fmt::format("target '{}': {}: {}", t.name, field, what));
  };
  if (t.cols < 1 || t.rows < 1) bad("cols/rows", "must be at least 1");
  if (t.type == TargetType::checkerboard) {
    if (t.cols < 2 || t.rows < 2)
      bad("cols/rows", "a checkerboard needs at least 2 x 2 inner corners");
    if (!(t.square > 0)) bad("square", "must be > 0 m");
  } else {
    if (!(t.tag_size > 0)) bad("tag_size", "must be > 0 m");
    if (!(t.tag_spacing > 0) || t.tag_spacing > 2)
      bad("tag_spacing", "must be in (0, 2] (gap / tag size)");
    if (t.cols * t.rows > 587) bad("cols/rows", "tag36h11 has 587 tags");
  }
  if (!(t.thickness >= 0) || t.thickness > kMaxBoardThickness)
    bad("thickness", fmt::format("must be in [0, {}] m", kMaxBoardThickness));
  if (t.cols > kMaxTargetCorners || t.rows > kMaxTargetCorners)
    bad("cols/rows", fmt::format("{} x {}: at most {} a side", t.cols, t.rows, kMaxTargetCorners));
  if (!std::isfinite(t.margin)) bad("margin", "must be a finite number of m");
  const Outline o = outline(t);
  if (!(o.width() <= kMaxTargetSide && o.height() <= kMaxTargetSide)) {
    bad("size", fmt::format("the board would be {:.4g} x {:.4g} m; at most {} m a side", o.width(),
                            o.height(), kMaxTargetSide));
  }
}

std::vector<Eigen::Vector3d> object_points(const Target& t) {
  std::vector<Eigen::Vector3d> pts;
  if (t.type == TargetType::checkerboard) {
    for (int j = 0; j < t.rows; ++j) {
      for (int i = 0; i < t.cols; ++i) pts.emplace_back(i * t.square, j * t.square, 0.0);
    }
    return pts;
  }
  const double pitch = t.tag_size * (1.0 + t.tag_spacing);
  auto coord = [&](int k) { return (k / 2) * pitch + (k % 2) * t.tag_size; };
  for (int n = 0; n < 2 * t.rows; ++n) {
    for (int m = 0; m < 2 * t.cols; ++m) pts.emplace_back(coord(m), coord(n), 0.0);
  }
  return pts;
}

Eigen::Vector2d board_points_extent(const Target& t) {
  const double pitch =
      t.type == TargetType::checkerboard ? t.square : t.tag_size * (1 + t.tag_spacing);
  const double last = t.type == TargetType::checkerboard ? 0.0 : t.tag_size;
  return {(t.cols - 1) * pitch + last, (t.rows - 1) * pitch + last};
}

Eigen::Vector2d board_warp_basis(const Target& t, double x, double y) {
  return board_warp_basis(board_points_extent(t).cwiseInverse(), x, y);
}

Outline outline(const Target& t) {
  Outline o;
  if (t.type == TargetType::checkerboard) {
    const double margin = t.margin < 0 ? t.square : t.margin;
    o.x_min = -t.square - margin;
    o.y_min = -t.square - margin;
    o.x_max = t.cols * t.square + margin;
    o.y_max = t.rows * t.square + margin;
  } else {
    const double gap = t.tag_size * t.tag_spacing;
    const double pitch = t.tag_size + gap;
    const double margin = t.margin < 0 ? gap : t.margin;
    o.x_min = -gap - margin;
    o.y_min = -gap - margin;
    o.x_max = t.cols * pitch + margin;
    o.y_max = t.rows * pitch + margin;
  }
  return o;
}

Pattern::Pattern(const Target& target) : target_(target) {
  validate(target);
  if (target.type != TargetType::aprilgrid) return;
  apriltag_family_t* family = tag36h11_create();
  const int n = target.cols * target.rows;
  tag_bits_.resize(n);
  for (int id = 0; id < n; ++id) {
    std::array<uint8_t, 36> bits{};
    for (uint32_t i = 0; i < family->nbits; ++i) {
      const bool white = (family->codes[id] >> (family->nbits - 1 - i)) & 1ULL;
      // bit_x, bit_y in 1..6 inside the 1-bit-bordered 8 x 8 tag. Laid out as they are, OpenCV's
      // aruco (DICT_APRILTAG_36h11) reads the tag rotated by 180 degrees, so they are turned here:
      // the printed tag is then upright, its first corner (aruco's top-left) at the top left.
      const int x = 6 - static_cast<int>(family->bit_x[i]),
                y = 6 - static_cast<int>(family->bit_y[i]);
      bits[y * 6 + x] = white ? 1 : 0;
    }
    tag_bits_[id] = bits;
  }
  tag36h11_destroy(family);
}

namespace {

// Where z lies along one axis of an AprilGrid: the pitch it is in (-1 the margin before the
// first tag; each pitch is [gap | tag], shifted by one gap) and, within it, 0 in the gap or
// 1 + the tag's cell (0-9) as printed along the axis.
std::pair<long, long> aprilgrid_axis(const Target& t, double z) {
  const double gap = t.tag_size * t.tag_spacing, pitch = t.tag_size + gap;
  const double u = z + gap;
  const long c = static_cast<long>(std::floor(u / pitch));
  const double du = u - c * pitch;  // 0..pitch; the first `gap` is the gap
  if (du < gap) return {c, 0};
  return {c, 1 + std::clamp(static_cast<long>((du - gap) / t.tag_size * 10.0), 0L, 9L)};
}

}  // namespace

std::pair<long, long> Pattern::cell(double x, double y) const {
  const Target& t = target_;
  if (t.type == TargetType::checkerboard)
    return {static_cast<long>(std::floor(x / t.square)),
            static_cast<long>(std::floor(y / t.square))};
  const auto [c, kx] = aprilgrid_axis(t, x);
  const auto [r, ky] = aprilgrid_axis(t, y);
  return {c * 11 + kx, r * 11 + ky};
}

double Pattern::albedo(double x, double y) const {
  const Target& t = target_;
  if (t.type == TargetType::checkerboard) {
    const auto [i, j] = cell(x, y);
    if (i < -1 || j < -1 || i > t.cols - 1 || j > t.rows - 1) return 1.0;  // margin
    return ((i + j) % 2 == 0) ? 0.0 : 1.0;  // the square diagonal to the origin corner is black
  }
  // Tag column c and row r (or the gaps before them), and the cell within.
  const auto [c, kx] = aprilgrid_axis(t, x);
  const auto [r, ky] = aprilgrid_axis(t, y);
  const bool in_gap_x = kx == 0, in_gap_y = ky == 0;
  if (c < 0 || r < 0 || c > t.cols || r > t.rows) return 1.0;  // margin
  if (in_gap_x && in_gap_y) return 0.0;                        // the small squares at tag corners
  if (in_gap_x || in_gap_y || c == t.cols || r == t.rows) return 1.0;
  // Inside tag (c, r): 10 x 10 cells, a 2-cell black border around 6 x 6 data bits.
  const long cx = kx - 1, row = 9 - (ky - 1);  // printed rows go downwards
  if (cx < 2 || cx > 7 || row < 2 || row > 7) return 0.0;
  return tag_bits_[r * t.cols + c][(row - 2) * 6 + (cx - 2)];
}

}  // namespace rigcal::camera
