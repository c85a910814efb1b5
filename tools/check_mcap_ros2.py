"""Open a log written by peopletrack with Python mcap-ros2-support (Foxglove's reader, a separate
implementation) and check topic counts and values against the JSON the writer produced.

Usage: check_mcap_ros2.py LOG.mcap EXPECTED.json   (exit status 1 on any mismatch)
"""
import json
import math
import sys
from collections import Counter

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory


def main(log_path, expected_path):
    expected = json.load(open(expected_path))
    frames = expected["frames"]
    counts = Counter()
    problems = []
    with open(log_path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        header = reader.get_header()
        if header.profile != "ros2":
            problems.append(f"profile is {header.profile!r}, not 'ros2'")
        for schema, channel, message, msg in reader.iter_decoded_messages():
            i = counts[channel.topic]
            counts[channel.topic] += 1
            want = frames[i]
            if message.log_time != want["log_time"]:
                problems.append(f"{channel.topic}[{i}] log_time {message.log_time} != {want['log_time']}")
            if channel.topic == "/scan":
                got = list(msg.ranges)
                for k, (g, w) in enumerate(zip(got, want["ranges"])):
                    if w == "NaN":
                        if not math.isnan(g):
                            problems.append(f"/scan[{i}] range {k}: {g} is not NaN")
                    elif abs(g - w) > 1e-6:
                        problems.append(f"/scan[{i}] range {k}: {g} != {w}")
                if [msg.header.stamp.sec, msg.header.stamp.nanosec] != want["stamp"]:
                    problems.append(f"/scan[{i}] stamp differs")
            elif channel.topic == "/cam_0/image_raw":
                if list(msg.data) != want["image"] or msg.encoding != "rgb8" or msg.step != 12:
                    problems.append(f"image[{i}] differs")
            elif channel.topic == "/cam_0/camera_info":
                if list(msg.d) != [-0.25, 0.1, 0.0, 0.0, 0.0] or msg.k[0] != 2.0 or msg.distortion_model != "plumb_bob":
                    problems.append(f"camera_info[{i}] differs")
            elif channel.topic == "/tf":
                if abs(msg.transforms[0].transform.translation.x - want["tf_x"]) > 1e-12:
                    problems.append(f"tf[{i}] differs")
            elif channel.topic == "/custom":
                if msg.name != want["custom_name"] or msg.inner[0].big != want["custom_big"]:
                    problems.append(f"custom[{i}] differs: {msg}")
                if len(msg.values) != want["custom_values"] or list(msg.triple)[:2] != [1, 2]:
                    problems.append(f"custom[{i}] arrays differ")
    if dict(counts) != expected["counts"]:
        problems.append(f"counts {dict(counts)} != {expected['counts']}")
    for p in problems[:20]:
        print("MISMATCH:", p)
    if problems:
        print(f"FAILED: {len(problems)} mismatches")
        return 1
    total = sum(counts.values())
    print(f"OK: mcap-ros2-support read {total} messages on {len(counts)} topics, all values equal")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:3]))
