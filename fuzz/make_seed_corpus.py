#!/usr/bin/env python3
"""Writes the seed corpus of the frame-decoder fuzz target (fuzz/corpus/frame_decoder/seed-*).

An independent encoder of the wire format (docs/protocol.md), with its own bit-wise
CRC-16/CCITT-FALSE. Deterministic: rerunning rewrites the same files. libFuzzer's own finds
are merged into the same directory by `make fuzz` under their hash names.
"""
import os
import random
import struct

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "frame_decoder")


def crc16(data: bytes, crc: int = 0xFFFF) -> int:
    for b in data:
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc


assert crc16(b"123456789") == 0x29B1


def frame(ftype: int, seq: int, payload: bytes) -> bytes:
    body = bytes([len(payload), ftype, seq]) + payload
    return b"\xA5\x5A" + body + struct.pack("<H", crc16(body))


def set_commands(seq, cmds):
    return frame(0x01, seq, struct.pack("<%dh" % len(cmds), *cmds))


def set_limits(seq, lo, hi):
    return frame(0x02, seq, struct.pack("<hh", lo, hi))


def heartbeat(seq):
    return frame(0x03, seq, b"")


def zero(seq, mask):
    return frame(0x04, seq, struct.pack("<I", mask))


def counts(seq, t, flags, cs):
    return frame(0x81, seq, struct.pack("<II%di" % len(cs), t, flags, *cs))


def main():
    os.makedirs(OUT, exist_ok=True)
    rng = random.Random(3)
    noise = lambda n: bytes(rng.randrange(256) for _ in range(n))
    c24 = [(-1) ** i * i * 4099 for i in range(24)]
    seeds = {
        "heartbeat": heartbeat(0),
        "set_limits": set_limits(1, 0, 4095),
        "set_limits_extremes": set_limits(2, -32768, 32767),
        "zero_all": zero(3, 0xFFFFFFFF),
        "zero_some": zero(4, 0b101),
        "set_commands_0": set_commands(5, []),
        "set_commands_8": set_commands(6, list(range(0, 800, 100))),
        "set_commands_24": set_commands(7, [i * 150 for i in range(24)]),
        "set_commands_32": set_commands(8, [-32768 + i * 2000 for i in range(32)]),
        "counts_0": counts(9, 0, 0, []),
        "counts_3": counts(10, 123456, 0x20, [1, -1, 8388607]),
        "counts_24": counts(11, 0xFFFFFFFF, 0x08, c24),
        "counts_32": counts(12, 42, 0xFF, [-(2 ** 31)] + list(range(31))),
        "session": heartbeat(0) + set_limits(1, 0, 4095) + set_commands(2, [100] * 24)
        + counts(2, 1000, 0, c24) + set_commands(3, [200] * 24) + counts(3, 2000, 0, c24),
        "truncated_counts": counts(13, 5, 0, c24)[:60],
        "truncated_header": b"\xA5\x5A\x08",
        "truncated_crc": heartbeat(14)[:-1],
        "bad_crc_payload": bytearray(set_commands(15, [1, 2, 3, 4])),
        "bad_crc_last": bytearray(counts(16, 7, 0, [5, 6])),
        "bad_length_over": b"\xA5\x5A\xFF\x81\x00" + noise(20),
        "bad_length_type": b"\xA5\x5A\x02\x03\x00\x00\x00" + heartbeat(17),
        "bad_length_odd": b"\xA5\x5A\x03\x01\x00\x01\x02\x03\x00\x00" + heartbeat(18),
        "bad_type": b"\xA5\x5A\x00\x7F\x00\x00\x00" + heartbeat(19),
        "noise_between": noise(17) + heartbeat(20) + noise(40) + counts(21, 1, 0, c24) + noise(5)
        + set_commands(22, [0] * 24) + noise(3),
        "false_header": b"\xA5\x5A\x88\x81\x00" + heartbeat(23) + heartbeat(24) + bytes(140),
        "sync_runs": b"\xA5" * 10 + b"\x5A" * 3 + b"\xA5\x5A" * 5 + heartbeat(25),
        "only_noise": noise(200),
        "empty": b"",
        "back_to_back_heartbeats": b"".join(heartbeat(s) for s in range(30)),
        "nested_sync_in_payload": set_commands(26, [0x5AA5, 0x5AA5, -0x5A5B, 0x0303]),
    }
    seeds["bad_crc_payload"][7] ^= 0x40
    seeds["bad_crc_last"][-1] ^= 0x01
    for name, data in seeds.items():
        with open(os.path.join(OUT, "seed-" + name), "wb") as f:
            f.write(bytes(data))
    print(f"{len(seeds)} seeds in {OUT}")


if __name__ == "__main__":
    main()
