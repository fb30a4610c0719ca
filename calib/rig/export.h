#pragma once
// Exports of the rig into the files other tools load without edits (doc/exports.md).
// Each function returns the file's text; export_files() names the files for `rigcal rig convert`.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/io/files.h"
#include "rigcal/rig/rig.h"

namespace rigcal::rig {

enum class ExportFormat { rigcal, vbr, kalibr, opencv, opencv_sample, ros, mrcal };
ExportFormat export_format_from_string(std::string_view name);  // throws, listing the names
std::string_view to_string(ExportFormat format);
// True when the format writes a folder: one file per camera (ros, mrcal), or OpenCV's stereo_calib
// sample's two files (opencv-sample).
bool writes_folder(ExportFormat format);

struct ExportOptions {
  // The IMU whose T_cam_imu and timeshift_cam_imu go into a Kalibr camchain. Empty: the sensor
  // named "imu" when there is one, else the first IMU, else none.
  std::string kalibr_imu;
};

// Kalibr camchain (camchain-imucam.yaml when an IMU is there): cam0, cam1, ... in rig order with
// camera_model, intrinsics, distortion_model, distortion_coeffs, resolution, rostopic,
// cam_overlaps, T_cn_cnm1 (cam_n from cam_n-1) and T_cam_imu + timeshift_cam_imu
// (t_imu = t_cam + shift). Throws for radtan with k3 != 0 (Kalibr's radtan has four coefficients).
std::string kalibr_camchain_yaml(const Rig& rig, const ExportOptions& options = {});

// OpenCV FileStorage YAML for the first one or two cameras, one file: K1 D1 (K2 D2), image_size1
// (image_size2), R T E F as cv::stereoCalibrate names them (p2 = R p1 + T, metres) and the
// rectification R1 R2 P1 P2 Q of cv::stereoRectify (cv::fisheye for equidistant), zero disparity,
// alpha (balance) 0. Not the stereo_calib sample's two files (intrinsics.yml M1 D1 M2 D2,
// extrinsics.yml), doc/exports.md.
std::string opencv_yaml(const Rig& rig);
// The two files OpenCV's stereo_calib sample writes, for the first two cameras: intrinsics.yml
// (M1 D1 M2 D2) and extrinsics.yml (R T R1 R2 P1 P2 Q: p2 = R p1 + T, T in metres where the
// sample's is in its square-size units; the rectification at alpha 1, every source pixel kept,
// as the sample asks). Throws without a pair of the same lens model and image size.
struct OpenCvSampleFiles {
  std::string intrinsics, extrinsics;
};
OpenCvSampleFiles opencv_sample_files(const Rig& rig);

// ROS camera_info YAML (camera_calibration_parsers) of one camera. With a stereo pair of equal
// image size, the rectification and projection matrices are those of stereo rectification
// (ROS's convention: the second camera's P has Tx = -fx' * baseline); else R = I, P = [K | 0].
std::string ros_camera_info_yaml(const Rig& rig, std::string_view camera);

// mrcal .cameramodel of one camera: LENSMODEL_OPENCV4 or OPENCV5 for radtan, numbers lossless,
// extrinsics = rt_cam_ref with the rig's base frame as mrcal's reference frame. The text is
// checked by reading it back with libmrcal (mrcal_read_cameramodel_string). Throws for
// equidistant cameras: mrcal 2.2 has no Kannala-Brandt model.
std::string mrcal_cameramodel(const Rig& rig, std::string_view camera);

// What a VBR-only file (rig_to_vbr_yaml) leaves out of this rig, a line each: clock offsets and
// drifts, rigid attachments, rigcal's section (provenance, notes). Empty when nothing is lost.
std::vector<std::string> vbr_drops(const Rig& rig);

// The files `rigcal rig convert --to FORMAT --out OUT` writes: OUT itself for single-file formats,
// OUT/<camera>.yaml (ros) or OUT/<camera>.cameramodel (mrcal) for the per-camera ones.
std::vector<io::OutputFile> export_files(const Rig& rig, ExportFormat format,
                                         const std::filesystem::path& out,
                                         const ExportOptions& options = {});

}  // namespace rigcal::rig
