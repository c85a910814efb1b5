"""Read two-channel audio written by peopletrack back with Python mcap-ros2-support (Foxglove's
reader, a separate implementation) and check that the samples equal what was written.

Usage:
  check_audio_ros2.py fixture LOG.mcap EXPECTED.json   the fixture's samples vs the JSON the
                                                       writer produced (every sample)
  check_audio_ros2.py wav LOG.mcap TOPIC FILE.wav      a session's topic vs the WAV file
                                                       `peopletrack wav` wrote from it
Exit status 1 on any mismatch.
"""
import json
import struct
import sys
import wave

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory


def read_audio(log_path, topic):
    """(AudioInfo fields, interleaved int16 samples, header stamps) of one topic."""
    info_topic = topic[: -len("audio")] + "audio_info" if topic.endswith("audio") else topic + "_info"
    info = None
    samples = []
    stamps = []
    with open(log_path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, message, msg in reader.iter_decoded_messages(topics=[topic, info_topic]):
            if channel.topic == info_topic:
                if schema.name != "audio_common_msgs/msg/AudioInfo":
                    raise SystemExit(f"{info_topic}: schema {schema.name}")
                info = (msg.channels, msg.sample_rate, msg.sample_format, msg.bitrate, msg.coding_format)
            else:
                if schema.name != "audio_common_msgs/msg/AudioDataStamped":
                    raise SystemExit(f"{topic}: schema {schema.name}")
                data = bytes(msg.audio.data)
                samples.extend(struct.unpack(f"<{len(data) // 2}h", data))
                stamps.append(msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)
    return info, samples, stamps


def check_fixture(log_path, expected_path):
    want = json.load(open(expected_path))
    info, samples, stamps = read_audio(log_path, want["topic"])
    problems = []
    if list(info) != want["info"]:
        problems.append(f"AudioInfo {info} != {want['info']}")
    if samples != want["samples"]:
        bad = next((i for i, (a, b) in enumerate(zip(samples, want["samples"])) if a != b), None)
        problems.append(f"{len(samples)} samples vs {len(want['samples'])}; first difference at {bad}")
    if stamps != want["stamps"]:
        problems.append("chunk stamps differ")
    return problems, len(samples)


def check_wav(log_path, topic, wav_path):
    info, samples, _ = read_audio(log_path, topic)
    problems = []
    with wave.open(wav_path, "rb") as w:
        if (w.getnchannels(), w.getframerate(), w.getsampwidth()) != (info[0], info[1], 2):
            problems.append(f"WAV format {w.getnchannels()} ch {w.getframerate()} Hz != {info}")
        raw = w.readframes(w.getnframes())
    wav = list(struct.unpack(f"<{len(raw) // 2}h", raw))
    if wav != samples:
        bad = next((i for i, (a, b) in enumerate(zip(wav, samples)) if a != b), None)
        problems.append(f"{len(wav)} WAV samples vs {len(samples)} in the log; first difference at {bad}")
    return problems, len(samples)


def main(argv):
    if len(argv) == 4 and argv[1] == "fixture":
        problems, n = check_fixture(argv[2], argv[3])
    elif len(argv) == 5 and argv[1] == "wav":
        problems, n = check_wav(argv[2], argv[3], argv[4])
    else:
        raise SystemExit(__doc__)
    for p in problems:
        print("MISMATCH:", p)
    print(f"{argv[2]}: {n} samples read back with mcap-ros2-support, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
