#!/usr/bin/python3
"""Writes the bag seeds of tests/fuzz/corpus/bag/: small ROS1 bags (no compression, LZ4, BZ2)
holding one or a few messages of every type rigcal converts. Needs Debian's python3-rosbag and
python3-sensor-msgs (the system Python): /usr/bin/python3 tests/fuzz/make_bag_seeds.py"""
import os
import struct

import genpy
import rosbag
from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import Image, Imu, NavSatFix, PointCloud2, PointField

here = os.path.dirname(os.path.abspath(__file__))
out = os.path.join(here, "corpus", "bag")
os.makedirs(out, exist_ok=True)


def stamp(k):
    return genpy.Time(100 + k // 10, (k % 10) * 100000000)


def messages():
    for k in range(3):
        m = Imu()
        m.header.stamp = stamp(k)
        m.orientation.w = 1.0
        m.angular_velocity.z = 0.1 * k
        m.linear_acceleration.z = 9.81
        yield "/imu/data", m, stamp(k)
    c = PointCloud2()
    c.header.stamp = stamp(0)
    c.height, c.width = 1, 4
    c.fields = [PointField("x", 0, 7, 1), PointField("y", 4, 7, 1), PointField("z", 8, 7, 1),
                PointField("intensity", 12, 7, 1), PointField("t", 16, 6, 1)]
    c.point_step, c.row_step = 20, 80
    c.data = b"".join(struct.pack("<4fI", 1.0 + i, 2.0, 0.5, 10.0, 1000 * i) for i in range(4))
    yield "/ouster/points", c, stamp(0)
    i = Image()
    i.header.stamp = stamp(1)
    i.height, i.width, i.encoding, i.step = 16, 16, "bayer_rggb8", 16
    i.data = bytes((r * 16 + c) % 256 for r in range(16) for c in range(16))
    yield "/camera_left/image_raw", i, stamp(1)
    f = NavSatFix()
    f.header.stamp = stamp(2)
    f.latitude, f.longitude, f.altitude = 41.89, 12.49, 50.0
    f.position_covariance = [0.0004, 0, 0, 0, 0.0004, 0, 0, 0, 0.0025]
    f.position_covariance_type = 2
    yield "/gps/fix", f, stamp(2)
    p = PoseStamped()
    p.header.stamp = stamp(2)
    p.pose.orientation.w = 1.0
    yield "/ins/pose", p, stamp(2)


for name, compression in (("plain.bag", "none"), ("lz4.bag", "lz4"), ("bz2.bag", "bz2")):
    with rosbag.Bag(os.path.join(out, name), "w", compression=compression) as bag:
        for topic, msg, t in messages():
            bag.write(topic, msg, t)
with rosbag.Bag(os.path.join(out, "empty.bag"), "w") as bag:
    pass

# The same messages serialized, for fuzz_ros_messages: the first byte chooses the decoder.
import io

kind = {"/ouster/points": 0, "/camera_left/image_raw": 1, "/imu/data": 2, "/gps/fix": 3,
        "/ins/pose": 4}
raw = os.path.join(here, "corpus", "ros_messages")
os.makedirs(raw, exist_ok=True)
for n, (topic, msg, t) in enumerate(messages()):
    buf = io.BytesIO()
    msg.serialize(buf)
    with open(os.path.join(raw, "%s_%d.bin" % (topic.strip("/").replace("/", "_"), n)), "wb") as f:
        f.write(bytes([kind[topic]]) + buf.getvalue())
