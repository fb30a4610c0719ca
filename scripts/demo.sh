#!/usr/bin/env bash
# `make demo`: the main job on the bundled sample. Today: check the sample rig's calibration YAML,
# show it, and write it in every export format; then the calibration steps on a simulated session
# (cameras, clock offset). Each calibration step extends this script.
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
rigcal="$root/$build/bin/rigcal"
[[ -x "$rigcal" ]] || rigcal="$build/bin/rigcal"
sample="$root/data/sample_rig.yaml"
out="$root/$build/demo"
rm -rf "$out"
mkdir -p "$out"

echo "== rigcal demo: the sample rig ($sample)"
"$rigcal" rig validate "$sample"
echo
"$rigcal" rig show "$sample"
echo
echo "== exports"
"$rigcal" rig convert "$sample" --to rigcal --out "$out/calib.yaml"
"$rigcal" rig convert "$sample" --to vbr    --out "$out/vbr_calib.yaml"
"$rigcal" rig convert "$sample" --to kalibr --out "$out/camchain-imucam.yaml"
"$rigcal" rig convert "$sample" --to opencv --out "$out/opencv_stereo.yaml"
"$rigcal" rig convert "$sample" --to ros    --out "$out/ros"
"$rigcal" rig convert "$sample" --to mrcal  --out "$out/mrcal"
echo
echo "The calibration YAML and its exports are in $out:"
(cd "$out" && find . -type f | sort | sed 's|^\./|  |')

echo
echo "== trajectory benchmark: a synthetic 1.5 km drive and an estimate with 0.2 % scale drift"
bench_in="$root/data/sample_bench"
"$rigcal" bench --gt "$bench_in/drive_gt.txt" --est "$bench_in/drive_es.txt" --report "$out/bench"
echo
"$rigcal" bench --gt "$bench_in/drive_gt.txt" --est "$bench_in/drive_es.txt" --convention kitti \
  --association nearest | tail -n 3
echo
echo "Benchmark report (bench.json, trajectory_top.svg, ate_along.svg) in $out/bench"

echo
echo "== simulated session of the sample rig (truth in $out/sim/truth.yaml and truth.json)"
printf "stereo:\n  views: 12\nscans:\n  count: 3\nlidar_camera:\n  pairs: 8\n" > "$out/sim.yaml"
"$rigcal" simulate --out "$out/sim" --config "$out/sim.yaml"
echo
"$rigcal" bench --gt "$out/sim/trajectories/truth_lidar.tum" \
  --est "$out/sim/trajectories/lidar_odometry.tum" | sed -n '1,8p'

echo
echo "== camera calibration of the simulated stereo images (truth: the sample rig)"
"$rigcal" cameras --session "$out/sim/stereo" --target "$root/targets/a3_checkerboard_8x5_40mm.yaml" \
  --rig "$sample" --out "$out/cameras/calib.yaml" --report "$out/cameras/report"
echo "true values: cam_l fx 1085.3 fy 1084.7 cx 701.2 cy 349.6; baseline 0.4985 m (data/sample_rig.yaml)"

echo
echo "== clock offset between the simulated session's two IMUs (truth: imu time_offset -0.0031 s)"
"$rigcal" time-offset --session "$out/sim" --rig "$out/cameras/calib.yaml" \
  --out "$out/time_offset/calib.yaml" --report "$out/time_offset/report"

echo
echo "== LiDAR-camera extrinsic from the simulated board pairs (truth: the sample rig's cam_r)"
"$rigcal" lidar-camera --session "$out/sim" --target "$root/targets/a3_checkerboard_8x5_40mm.yaml" \
  --rig "$out/time_offset/calib.yaml" --out "$out/lidar_camera/calib.yaml" \
  --report "$out/lidar_camera/report"

echo
echo "== GNSS/INS-to-LiDAR extrinsic from the simulated trajectories (truth: the sample rig's gnss)"
"$rigcal" hand-eye --lidar "$out/sim/trajectories/lidar_odometry.tum" \
  --gnss "$out/sim/trajectories/gnss_ins.tum" --rig "$out/lidar_camera/calib.yaml" \
  --estimate-offset --out "$out/hand_eye/calib.yaml" --report "$out/hand_eye/report"
echo "The session's calibration, step by step: $out/hand_eye/calib.yaml"
