#pragma once
// Reports of the camera step (doc/cameras.md): the detections cache in mrcal's corners.vnl format
// (`filename x y level`, `filename - - -` for an image or a corner without detection), the JSON
// report and the quick-look PNGs.
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rigcal/camera/calibrate.h"
#include "rigcal/camera/uncertainty.h"
#include "rigcal/report/png.h"

namespace rigcal::camera {

// One detection a named image; mrcal reads this file with --corners-cache.
// `saddle_fit`: the corners were fitted as saddles (DetectOptions::fit_saddles), which the
// header says: a cache holds for a run only when written with the same refinement.
std::string corners_vnl(const Target& target, const std::vector<std::string>& images,
                        const std::vector<Detection>& detections, bool saddle_fit = false);
// Detections by image name, when the file was written for this target and refinement (else
// empty).
std::map<std::string, Detection> parse_corners_vnl(std::string_view text, const Target& target,
                                                   bool saddle_fit = false);

struct CameraReportInput {
  std::vector<std::string> camera_names;
  std::vector<std::vector<std::string>> images;             // per camera, per frame ("" where none)
  std::vector<UncertaintyMap> uncertainty;                  // mrcal's definition, per camera
  std::vector<UncertaintyMap> uncertainty_intrinsics_only;  // for comparison
  double uncertainty_distance_m = 0;
  std::map<std::string, std::string> inputs;
};

nlohmann::json cameras_json(const CalibrationResult& result, const CameraReportInput& in);

// Quick looks (8-bit BGR): detected corners over an image; residual vectors (magnified) over the
// image area; coverage (where corners were seen); the uncertainty map.
cv::Mat corners_png(const cv::Mat& gray, const Detection& detection);
cv::Mat residuals_png(const CalibrationResult& result, int camera, int width, int height,
                      double magnify);
cv::Mat coverage_png(const CalibrationResult& result, int camera, int width, int height);

// Every corner's residual, one line each (`camera,view,point,u_px,v_px,residual_u_px,
// residual_v_px,outlier`, the residual projected - observed), for the HTML report's figures.
std::string residuals_csv(const CalibrationResult& result,
                          const std::vector<std::string>& camera_names);

// Where a camera's image holds too few inlier corners for its lens to be measured there: a half
// of the image with under a tenth of them, or a ninth of it (3 x 3 cells) with none. Empty when
// the board covered the image.
std::vector<std::string> coverage_warnings(const CalibrationResult& result, int camera,
                                           const std::string& name, int width, int height);
cv::Mat uncertainty_png(const UncertaintyMap& map, int width, int height);

}  // namespace rigcal::camera
