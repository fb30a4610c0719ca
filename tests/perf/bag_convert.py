#!/usr/bin/python3
"""The bag conversion benchmark (doc/performance.md, "Bags").

Writes a VBR-like bag of MB megabytes (rigcal_perf_write_bag), then times `rigcal convert` on it
and, in the same run, the peer: Debian's python3-rosbag iterating and deserializing the same
messages (what vbr-devkit's converter does before it writes anything). Each with its wall time,
throughput over the bag's size and peak memory (the largest resident set of the process); the
disk's own read and write speeds for scale. The page cache is dropped before each run where this
user may (root) unless --warm; the output says which.

    tests/perf/bag_convert.py BUILD_DIR WORK_DIR [--mb 2048] [--lz4] [--warm] [--keep]
"""
import argparse
import os
import resource
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def drop_caches(warm):
    os.sync()
    if warm:
        return "warm"
    try:
        with open("/proc/sys/vm/drop_caches", "w") as f:
            f.write("3\n")
        return "cold"
    except OSError:
        return "warm"


def timed(label, command, bag_bytes, warm):
    """Runs command alone (a fresh child, so that its peak memory is its own)."""
    cache = drop_caches(warm)
    # The child's peak RSS: measured by a wrapper process whose only child is the command.
    wrapper = ("import resource,subprocess,sys,time;t=time.monotonic();"
               "r=subprocess.run(sys.argv[1:],stdout=subprocess.PIPE,stderr=subprocess.PIPE);"
               "w=time.monotonic()-t;sys.stderr.buffer.write(r.stderr);"
               "sys.stdout.buffer.write(r.stdout);"
               "print('@@',w,resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss,r.returncode)")
    r = subprocess.run([sys.executable, "-c", wrapper] + command, capture_output=True, text=True)
    lines = r.stdout.strip().splitlines()
    if not lines or not lines[-1].startswith("@@"):
        sys.exit(f"{label}: could not be measured: {r.stderr}")
    _, wall, kb, rc = lines[-1].split()
    wall, kb, rc = float(wall), int(kb), int(rc)
    if rc != 0:
        sys.exit(f"{label}: exit {rc}\n{r.stderr}")
    print(f"{label:46s} {wall:7.2f} s {bag_bytes / 1e6 / wall:8.0f} MB/s {kb / 1024:7.0f} MB peak"
          f" ({cache} cache)", flush=True)
    return "\n".join(lines[:-1])


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("build")
    p.add_argument("work")
    p.add_argument("--mb", type=float, default=2048)
    p.add_argument("--lz4", action="store_true", help="LZ4-compressed chunks")
    p.add_argument("--warm", action="store_true", help="do not drop the page cache")
    p.add_argument("--keep", action="store_true", help="keep the bag (for a second run)")
    a = p.parse_args()
    os.makedirs(a.work, exist_ok=True)
    bag = os.path.join(a.work, "session.bag")
    rec = os.path.join(a.work, "recording")
    shutil.rmtree(rec, ignore_errors=True)
    if not (a.keep and os.path.exists(bag)):
        subprocess.run([os.path.join(a.build, "bin", "rigcal_perf_write_bag"), bag, "--mb",
                        str(a.mb)] + (["--lz4"] if a.lz4 else []), check=True)
    size = os.path.getsize(bag)
    print(f"bag: {size / 1e6:.0f} MB{' (LZ4)' if a.lz4 else ''}", flush=True)
    timed("disk read (dd of the bag)", ["dd", f"if={bag}", "of=/dev/null", "bs=4M"], size, a.warm)
    out = timed("rigcal convert", [os.path.join(a.build, "bin", "rigcal"), "convert", bag,
                                   "--out", rec], size, a.warm)
    files = sum(len(f) for _, _, f in os.walk(rec))
    written = sum(os.path.getsize(os.path.join(d, n)) for d, _, f in os.walk(rec) for n in f)
    print(f"  recording: {written / 1e6:.0f} MB in {files} files")
    shutil.rmtree(rec)
    try:
        import rosbag  # noqa: F401
        peer = timed("peer: python3-rosbag, messages deserialized",
                     [sys.executable, os.path.join(HERE, "rosbag_peer.py"), bag], size, a.warm)
        print(f"  {peer.strip()}")
    except ImportError:
        print("peer: python3-rosbag is not installed (apt install python3-rosbag): not measured")
    copy = os.path.join(a.work, "copy")
    timed("disk write (dd copy of the bag, fdatasync)",
          ["dd", f"if={bag}", f"of={copy}", "bs=4M", "conv=fdatasync"], size, a.warm)
    os.remove(copy)
    if not a.keep:
        os.remove(bag)


if __name__ == "__main__":
    main()
