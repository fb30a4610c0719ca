#pragma once
// What every step's JSON report writes the same way: numbers that may be undefined, vectors and
// poses.
#include <Eigen/Core>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "rigcal/core/se3.h"

namespace rigcal::report {

// The number, or null where it is NaN or infinite (JSON has neither).
inline nlohmann::json finite_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}
// [x, y, z]
inline nlohmann::json vector_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
// The 4 x 4 matrix, row by row.
inline nlohmann::json pose_json(const SE3& T) {
  const Eigen::Matrix4d m = T.matrix();
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

// The file text of a JSON document: indented by 2, a final newline, and any invalid UTF-8 in its
// strings (names and messages quoted from damaged input) written as U+FFFD instead of throwing.
inline std::string json_text(const nlohmann::json& j) {
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace rigcal::report
