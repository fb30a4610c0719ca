#!/usr/bin/env bash
# Runs one fuzz target for CTest (doc/testing.md, "Fuzzing").
#   run_fuzz.sh replay BIN TARGET SRC
#       every committed seed (SRC/corpus/TARGET) and regression input (SRC/regressions/TARGET),
#       each executed once; a crash fails.
#   run_fuzz.sh fuzz BIN TARGET SRC WORK SECONDS MAX_LEN DICT FIXTURES REPO
#       fuzzes for SECONDS from WORK/corpus/TARGET (kept between runs in the build tree) and the
#       seeds: the committed ones, the repository's own files and, when FIXTURES exists, the first
#       lines or bytes of some of its files (copied into WORK/seeds/TARGET, never into the sources).
set -euo pipefail
mode=$1 bin=$2 target=$3 src=$4
limits=(-rss_limit_mb=2048 -timeout=10)

if [[ $mode == replay ]]; then
  shopt -s nullglob
  files=("$src/regressions/$target"/* "$src/corpus/$target"/*)
  if [[ ${#files[@]} -eq 0 ]]; then
    echo "no committed seeds or regression inputs for $target: nothing to replay"
    exit 0
  fi
  echo "replaying ${#files[@]} inputs of $target"
  exec "$bin" "${limits[@]}" "${files[@]}"
fi

work=$5 seconds=$6 max_len=$7 dict=$8 fixtures=$9 repo=${10}
seeds=$work/seeds/$target corpus=$work/corpus/$target artifacts=$work/artifacts/$target
rm -rf "$seeds"
mkdir -p "$seeds" "$corpus" "$artifacts"
cp "$src/corpus/$target"/* "$seeds"/ 2>/dev/null || true

# The first N lines (text) or bytes (binary) of a file: a seed of libFuzzer's size.
lines() { [[ -f $2 ]] && head -n "$1" "$2" > "$seeds/$(basename "$2").head$1" || true; }
bytes() { [[ -f $2 ]] && head -c "$1" "$2" > "$seeds/$(basename "$2").head$1" || true; }
have_fixtures=0
[[ -d $fixtures ]] && have_fixtures=1
f=$fixtures
case $target in
  rig_yaml) cp "$repo"/data/*.yaml "$seeds"/ ;;
  target_yaml) cp "$repo"/targets/*.yaml "$seeds"/ ;;
  trajectory_tum)
    for t in "$repo"/data/sample_bench/*.txt; do lines 40 "$t"; done
    for t in "$f"/trajectories/evo/{freiburg1_xyz-groundtruth,fr2_desk_ORB,V102}.txt \
             "$f"/trajectories/vbr/campus_train0_gt.txt "$f"/trajectories/vbr/vbr_slam_benchmark/orbslam/*; do
      lines 40 "$t"
    done ;;
  trajectory_kitti)
    for t in "$f"/trajectories/evo/KITTI_00_ORB.txt "$f"/lidar/ouster_os1_128/*_poses_kitti.txt; do
      lines 40 "$t"
    done
    if [[ $have_fixtures == 1 ]]; then
      { head -n 20 "$f/trajectories/evo/KITTI_00_gt.txt"; echo "--times--"
        head -n 20 "$f/trajectories/evo/KITTI_00_gt_times.txt"; } > "$seeds/KITTI_00_gt_with_times.txt"
    fi ;;
  trajectory_euroc) lines 40 "$f/trajectories/evo/V102_groundtruth.csv" ;;
  rates_table)
    for t in "$f"/imu/li_init/{imu,IMU_meas}.txt "$f"/imu/lidar_imu_timeoffset/0_{omega,odom}.txt; do
      lines 40 "$t"
    done ;;
  point_cloud_pcd)
    for t in "$f"/lidar/kitti00_pcd/*.pcd; do bytes 65536 "$t"; break; done
    for t in "$f"/lidar_camera/acfr/*/pcd/*.pcd; do bytes 65536 "$t"; break; done ;;
  point_cloud_bin) for t in "$f"/lidar/kitti00_bin/*.bin; do bytes 65536 "$t"; break; done ;;
  image) # whole JPEGs under the length limit (a cut one would only test truncation)
    for t in "$f"/stereo/opencv_samples/left0{1,3}.jpg; do
      [[ -f $t && $(stat -c %s "$t") -le 65536 ]] && cp "$t" "$seeds"/ || true
    done ;;
  ouster) # a metadata JSON, the separator, the capture's first bytes (a few packets)
    for t in ouster_sdk/OS-1-32-G_v2.1.1_1024x10 ouster_sdk/crc_test ouster_sdk/duplicate_id \
             ouster_sdk/OS-0-32-U1_v2.2.0_1024x10; do
      if [[ -f $f/lidar/$t.json && -f $f/lidar/$t.pcap ]]; then
        { cat "$f/lidar/$t.json"; printf '\n--pcap--\n'; head -c 40000 "$f/lidar/$t.pcap"; } \
          > "$seeds/$(basename "$t").head"
      fi
    done ;;
esac
if [[ $have_fixtures == 1 ]]; then
  echo "seeds of $target: $(ls "$seeds" | wc -l) (fixtures from $fixtures included)"
else
  echo "seeds of $target: $(ls "$seeds" | wc -l); $fixtures absent: no fixture seeds"
fi

set +e
"$bin" "${limits[@]}" -max_total_time="$seconds" -max_len="$max_len" -dict="$dict" \
  -artifact_prefix="$artifacts/" -print_final_stats=1 "$corpus" "$seeds" 2>&1 | tee "$work/$target.log"
rc=${PIPESTATUS[0]}
set -e
runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/$target.log" | tail -1)
echo "$target: ${runs:-?} executions in ${seconds} s, corpus $(ls "$corpus" | wc -l) inputs"
if [[ $rc -ne 0 ]]; then
  echo "$target: FINDING (exit $rc). Reproduce: $bin <artifact above>; once fixed, commit the input" \
       "as tests/fuzz/regressions/$target/<what>, which every run replays." >&2
fi
exit "$rc"
