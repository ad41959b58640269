"""Writes the grids of scenes/smoke.toml and scenes/cloud-caustic.toml as Mitsuba .vol files
(binary, version 3, float32, one channel, x fastest): a rising smoke plume and a cloud.
Deterministic (a hashed value noise): running it again writes the same bytes.

    python3 scenes/volumes/make_volumes.py
"""

import math
import os
import struct


def hash01(i, j, k, seed):
    h = (i * 73856093) ^ (j * 19349663) ^ (k * 83492791) ^ (seed * 2654435761)
    h &= 0xFFFFFFFF
    h ^= h >> 13
    h = (h * 0x5BD1E995) & 0xFFFFFFFF
    h ^= h >> 15
    return h / 0xFFFFFFFF


def value_noise(x, y, z, seed):
    i, j, k = math.floor(x), math.floor(y), math.floor(z)
    fx, fy, fz = x - i, y - j, z - k
    sx, sy, sz = (f * f * (3 - 2 * f) for f in (fx, fy, fz))
    c = [[[hash01(i + a, j + b, k + d, seed) for d in (0, 1)] for b in (0, 1)] for a in (0, 1)]

    def lerp(a, b, t):
        return a + (b - a) * t

    x00 = lerp(c[0][0][0], c[1][0][0], sx)
    x10 = lerp(c[0][1][0], c[1][1][0], sx)
    x01 = lerp(c[0][0][1], c[1][0][1], sx)
    x11 = lerp(c[0][1][1], c[1][1][1], sx)
    return lerp(lerp(x00, x10, sy), lerp(x01, x11, sy), sz)


def fbm(x, y, z, seed, octaves=3):
    s, a, f, norm = 0.0, 1.0, 1.0, 0.0
    for o in range(octaves):
        s += a * value_noise(x * f, y * f, z * f, seed + o)
        norm += a
        a *= 0.5
        f *= 2.0
    return s / norm


def plume(x, y, z):
    """A column rising from the bottom centre, widening and thinning as it rises."""
    cx = 0.5 + 0.08 * math.sin(5.0 * y)
    cz = 0.5 + 0.06 * math.cos(4.0 * y)
    r = 0.07 + 0.28 * y
    d2 = ((x - cx) ** 2 + (z - cz) ** 2) / (r * r)
    core = math.exp(-3.0 * d2) * (1.0 - 0.6 * y) * min(1.0, y / 0.05)
    n = fbm(6.0 * x, 6.0 * y - 2.0, 6.0 * z, 11)
    v = core * (2.2 * n - 0.5)
    # Clear air around the plume: no thin haze filling the whole box.
    return v if v > 0.03 else 0.0


def cloud(x, y, z):
    """A lumpy ellipsoidal cloud filling most of its box."""
    d2 = ((x - 0.5) / 0.45) ** 2 + ((y - 0.5) / 0.35) ** 2 + ((z - 0.5) / 0.45) ** 2
    n = fbm(5.0 * x, 5.0 * y, 5.0 * z, 29)
    return max(0.0, 1.0 - d2 + 0.9 * (n - 0.5)) * 1.5


def write(path, res, f):
    values = []
    for k in range(res):
        for j in range(res):
            for i in range(res):
                values.append(f((i + 0.5) / res, (j + 0.5) / res, (k + 0.5) / res))
    with open(path, "wb") as out:
        out.write(b"VOL" + bytes([3]))
        out.write(struct.pack("<5i", 1, res, res, res, 1))
        out.write(struct.pack("<6f", 0, 0, 0, 1, 1, 1))
        out.write(struct.pack(f"<{len(values)}f", *values))


if __name__ == "__main__":
    here = os.path.dirname(os.path.abspath(__file__))
    write(os.path.join(here, "smoke.vol"), 48, plume)
    write(os.path.join(here, "cloud.vol"), 32, cloud)
