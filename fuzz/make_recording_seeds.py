#!/usr/bin/env python3
"""Writes the seed corpora of the recording-reader and config-loader fuzz targets:
fuzz/corpus/recording_reader/seed-* and fuzz/corpus/config_loader/seed-*.

Usage: fuzz/make_recording_seeds.py RECORDING_DIR
RECORDING_DIR is a recording made by `spidar-mr run --record DIR --record-frames png` (a second
is plenty); each CSV's header and first rows become a valid seed, and hand-made damage (a row cut
off, nan, garbage, time going back, a wrong header, CRLF) the others. A recording seed is one byte
for the file (0 device.csv, 1 fingertips.csv, 2 frames.csv, 3 scene.csv, 4 fits.csv,
5 session.json; fuzz/fuzz_recording_reader.cpp), one byte for device.csv's string count
(1 + byte % 32), then the text. Config seeds are configs/*.yaml and small damaged YAML.
"""
import glob
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
KINDS = {"device.csv": 0, "fingertips.csv": 1, "frames.csv": 2, "scene.csv": 3, "fits.csv": 4, "session.json": 5}


def write(folder, name, data):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "seed-" + name), "wb") as f:
        f.write(data)


def recording_seeds(rec):
    out = os.path.join(HERE, "corpus", "recording_reader")
    strings = json.load(open(os.path.join(rec, "session.json")))["string_count"]
    prefix = lambda kind: bytes([kind, (strings - 1) % 32])
    for name, kind in KINDS.items():
        text = open(os.path.join(rec, name), "rb").read()
        stem = name.split(".")[0]
        if kind == 5:
            write(out, stem, prefix(kind) + text)
            write(out, stem + "_v1", prefix(kind) + text.replace(b'"version": 2', b'"version": 1'))
            write(out, stem + "_bad_json", prefix(kind) + text[: len(text) // 2])
            continue
        lines = text.split(b"\n")[:4]  # the header and 3 rows
        good = b"\n".join(lines) + b"\n"
        write(out, stem, prefix(kind) + good)
        write(out, stem + "_crlf", prefix(kind) + good.replace(b"\n", b"\r\n"))
        write(out, stem + "_cut", prefix(kind) + good[:-9])
        write(out, stem + "_nan", prefix(kind) + good.replace(b",0.", b",nan", 1).replace(b",1,", b",nan,", 1))
        write(out, stem + "_garbage", prefix(kind) + good.replace(b"1", b"1x", 1))
        rows = lines[1:]
        write(out, stem + "_reversed", prefix(kind) + b"\n".join([lines[0]] + rows[::-1]) + b"\n")
        write(out, stem + "_header", prefix(kind) + good.replace(b",", b";", 1))
        write(out, stem + "_header_only", prefix(kind) + lines[0] + b"\n")
    write(out, "empty", bytes([0, 23]))


def config_seeds():
    out = os.path.join(HERE, "corpus", "config_loader")
    for path in sorted(glob.glob(os.path.join(HERE, "..", "configs", "*.yaml"))):
        write(out, os.path.basename(path)[:-5], open(path, "rb").read())
    write(out, "duplicate_key", b"name: a\nname: b\n")
    write(out, "deep", b"a: " + b"[" * 80 + b"]" * 80 + b"\n")
    write(out, "aliases", b"a: &a [1, 2, 3]\nb: &b [*a, *a, *a]\nc: [*b, *b, *b]\n")
    write(out, "map_key", b"? [1, 2]\n: 3\n")
    write(out, "not_a_map", b"- 1\n- 2\n")
    write(out, "tabs_and_nul", b"name:\t\"x\\0y\"\nfingers: 3\n")
    write(out, "fingers_wrong", b"name: x\nfingers:\n  - name: f\n    fulcrums: [[0, 0], [1, 2, 3]]\n")
    write(out, "numbers", b"a: 1e999\nb: -0x10\nc: .nan\nd: 9223372036854775808\n")
    write(out, "empty", b"")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    recording_seeds(sys.argv[1])
    config_seeds()
