#!/usr/bin/env bash
# `make demo`: the main job on the bundled sample. The sample rig's calibration YAML checked, shown
# and exported; a trajectory scored; then a simulated session calibrated in one command
# (`rigcal calibrate`, hand-eye on rigcal's own LiDAR odometry of the simulated walk) and
# published with two sequences (`rigcal publish`); the walk's ground truth from that odometry and
# the GNSS/INS into its sequence folder, with its map and the check of the simulated survey
# markers in it (`rigcal ground-truth`), scored against the truth (`rigcal bench`).
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
echo "Benchmark report (bench.json, trajectory.svg, ate.svg, rpe.svg) in $out/bench"

echo
echo "== simulated session of the sample rig (truth in $out/sim/truth.yaml and truth.json);"
echo "   the motion recording: a 30 s walk with the LiDAR's sweeps, for rigcal's own odometry"
printf "stereo:\n  views: 12\nscans:\n  count: 3\nlidar_camera:\n  pairs: 8\ntrajectories:\n  duration_s: 30\n  motion: walk\n  scans: true\n  markers: 6\n" > "$out/sim.yaml"
"$rigcal" simulate --out "$out/sim" --config "$out/sim.yaml"

echo
echo "== the whole session calibrated in one command, from the prior rig a mounting drawing gives"
echo "   (data/sample_prior_rig.yaml); $out/sim/session.yaml names which recording serves which step"
"$rigcal" calibrate "$out/sim" --rig "$root/data/sample_prior_rig.yaml" --out "$out/session"
echo
echo "== hand-eye's LiDAR odometry (rigcal's, $out/session/reports/hand_eye/lidar_odometry.tum)"
echo "   against the truth"
"$rigcal" bench --gt "$out/sim/trajectories/truth_lidar.tum" \
  --est "$out/session/reports/hand_eye/lidar_odometry.tum" | sed -n '1,7p'
echo
echo
echo "== the calibration against the truth (data/sample_rig.yaml)"
"$rigcal" rig show "$out/session/calib.yaml" | sed -n '1,12p'
echo "true: cam_l fx 1085.3 fy 1084.7 cx 701.2 cy 349.6; baseline 0.4985 m; imu and gnss offsets"
echo "-3.1 ms; gnss at [-0.0512 0.0034 -0.1395] m (data/sample_rig.yaml)"
echo
echo "== rigcal diff: the truth against the calibration, weighed by the calibration's sigmas"
echo "   (the page a person reads: $out/diff/report.html)"
"$rigcal" diff "$out/sim/truth.yaml" "$out/session/calib.yaml" --report "$out/diff" | \
  grep -E "^Poses|T_cam_r_cam_l|T_cam_r_lidar|T_gnss_lidar|^Camera|the same rays|report:"

echo
echo "== a rerun with unchanged inputs reuses every step"
"$rigcal" calibrate "$out/sim" --rig "$root/data/sample_prior_rig.yaml" --out "$out/session" | tail -n 7

echo
echo "== published with two recorded sequences (VBR layout: <place>/<seq>/vbr_calib.yaml)"
mkdir -p "$out/vbr/campus/campus_train0" "$out/vbr/campus/campus_train1"
"$rigcal" publish "$out/session/calib.yaml" "$out/vbr/campus/campus_train0" \
  "$out/vbr/campus/campus_train1" --formats vbr,rigcal,kalibr
echo "The session's calibration: $out/session/calib.yaml; the page to read: $out/session/report.html"

echo
echo "== the walk's ground truth (doc/ground-truth.md), written in its published sequence folder"
echo "   beside its calibration (rigcal_calib.yaml: it keeps the clock offsets vbr_calib.yaml"
echo "   drops): that odometry with its step covariances and the GNSS/INS positions in a pose"
echo "   graph, through the calibrated lever arm; then the LiDAR bundle adjustment over windows"
echo "   of the walk's sweeps, whose motions go into the pose graph again (about a minute on 2"
echo "   cores: 300 full OS0-128 sweeps); then the map, and in it the six survey markers the"
echo "   simulator placed beside the path, their distances against the survey's. Exit 3 would"
echo "   mean something the data cannot determine, said on stderr, the trajectory still written"
seq="$out/vbr/campus/campus_train0"
rc=0
"$rigcal" ground-truth "$out/sim" --rig "$seq/rigcal_calib.yaml" \
  --odometry "$out/session/reports/hand_eye/lidar_odometry.tum" \
  --gnss "$out/sim/trajectories/gnss_ins.tum" --out "$seq/campus_train0_gt.txt" \
  --markers "$out/sim/trajectories/markers.csv" --map "$out/ground_truth/campus_train0_map.ply" \
  --report "$out/ground_truth" || rc=$?
if [ "$rc" -ne 0 ] && [ "$rc" -ne 3 ]; then exit "$rc"; fi
echo "   the page to read: $out/ground_truth/report.html"
echo "   scored against the truth:"
"$rigcal" bench --gt "$out/sim/trajectories/truth_lidar.tum" --est "$seq/campus_train0_gt.txt" |
  sed -n '1,7p'
