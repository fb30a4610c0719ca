#!/usr/bin/python3
"""The peer of rigcal convert in the bag benchmark (doc/performance.md, "Bags"): Debian's
python3-rosbag iterating every message of the bags in time order, each deserialized into its
message class (what vbr-devkit's converter does before it writes anything), nothing written.

    python3 rosbag_peer.py BAG...
"""
import sys
import time

try:
    import rosbag
except ImportError:
    sys.exit("rosbag_peer.py: python3-rosbag is not installed (apt install python3-rosbag)")


def main(paths):
    count, start = 0, time.monotonic()
    bags = [rosbag.Bag(p) for p in paths]
    for bag in bags:  # one bag at a time: the benchmark's bag is one file
        for _topic, msg, _t in bag.read_messages():
            count += 1
            if isinstance(getattr(msg, "data", None), (bytes, bytearray)):
                len(msg.data)
        bag.close()
    print(f"{count} messages in {time.monotonic() - start:.2f} s")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
