#!/usr/bin/env python3
"""Makes the textures the scenes use, from nothing but formulas (rtsh ships
no image it did not make, except Spot's, which is public domain):

  sky.hdr    a 512x256 Radiance HDR sky, equirectangular (rtsh(5), "sky"):
             a blue gradient overhead, a bright horizon, a sun of radiance
             ~2000 at 35 degrees elevation, a dim brown ground below
  earth.png  a 1024x512 made-up planet, equirectangular: value-noise
             continents, ice caps, a latitude-dependent climate; the
             (0,0) corner is marked red so the texture's orientation can
             be checked by eye (it lands at the south-west, see rtsh(5))

Run: python3 scenes/textures/make_textures.py  (writes beside itself)."""
import math, os, struct, zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def rgbe(r, g, b):
    m = max(r, g, b)
    if m < 1e-32:
        return b"\0\0\0\0"
    e = math.frexp(m)[1]
    s = 256.0 / 2.0 ** e
    return bytes([min(255, int(r * s)), min(255, int(g * s)), min(255, int(b * s)), e + 128])


def sky(w=512, h=256):
    sun = (math.radians(40.0), math.radians(35.0))  # azimuth (u from the middle), elevation
    sd = (math.sin(sun[0]) * math.cos(sun[1]), math.sin(sun[1]), -math.cos(sun[0]) * math.cos(sun[1]))
    out = bytearray()
    for y in range(h):
        lat = math.pi * (0.5 - (y + 0.5) / h)
        for x in range(w):
            phi = 2 * math.pi * ((x + 0.5) / w - 0.5)
            d = (math.sin(phi) * math.cos(lat), math.sin(lat), -math.cos(phi) * math.cos(lat))
            if lat > 0:
                t = math.sin(lat) ** 0.5
                c = [1.0 * (1 - t) + 0.25 * t, 1.05 * (1 - t) + 0.45 * t, 1.1 * (1 - t) + 0.95 * t]
            else:
                t = min(1.0, -math.sin(lat) * 4)
                c = [0.35 * (1 - t) + 0.18 * t, 0.33 * (1 - t) + 0.14 * t, 0.3 * (1 - t) + 0.1 * t]
            cosa = sum(a * b for a, b in zip(d, sd))
            if cosa > math.cos(math.radians(2.5)):
                c = [150.0, 140.0, 120.0]
            elif cosa > 0.9:
                k = (cosa - 0.9) / 0.1
                c = [c[0] + 3 * k ** 8, c[1] + 2.7 * k ** 8, c[2] + 2.2 * k ** 8]
            out += rgbe(*c)
    hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w)
    with open(os.path.join(HERE, "sky.hdr"), "wb") as f:
        f.write(hdr + bytes(out))


def hash2(ix, iy, seed):
    n = (ix * 374761393 + iy * 668265263 + seed * 2147483647) & 0xFFFFFFFF
    n = ((n ^ (n >> 13)) * 1274126177) & 0xFFFFFFFF
    return ((n ^ (n >> 16)) & 0xFFFF) / 65535.0


def noise(x, y, period, seed):
    x0, y0 = math.floor(x), math.floor(y)
    fx, fy = x - x0, y - y0
    sx, sy = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy)
    def v(i, j):
        return hash2(int(i) % period, int(j), seed)
    a = v(x0, y0) * (1 - sx) + v(x0 + 1, y0) * sx
    b = v(x0, y0 + 1) * (1 - sx) + v(x0 + 1, y0 + 1) * sx
    return a * (1 - sy) + b * sy


def png(path, w, h, rows):
    raw = b"".join(b"\0" + bytes(r) for r in rows)
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    data += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(data)


def earth(w=1024, h=512):
    rows = []
    for y in range(h):
        lat = 90 - 180 * (y + 0.5) / h
        row = bytearray()
        for x in range(w):
            e, amp, f = 0.0, 1.0, 4
            for o in range(5):
                e += amp * noise(x * f / w, y * f / w, f, o)
                amp, f = amp * 0.5, f * 2
            e /= 1.9375
            if abs(lat) > 72 - 6 * e:
                c = (235, 240, 245)
            elif e > 0.53:
                k = min(1.0, (e - 0.53) * 5)
                dry = abs(abs(lat) - 25) < 10
                base = (190, 165, 110) if dry else (70, 120, 55)
                c = tuple(int(b * (1 - 0.4 * k) + 120 * 0.4 * k) for b in base)
            else:
                k = e / 0.53
                c = (int(15 + 30 * k), int(40 + 60 * k), int(110 + 60 * k))
            if x < 32 and y >= h - 32:
                c = (255, 0, 0)  # the (0,0) corner of the texture
            row += bytes(c)
        rows.append(row)
    png(os.path.join(HERE, "earth.png"), w, h, rows)


def flat_normal(w=16, h=16):
    png(os.path.join(HERE, "flat_normal.png"), w, h, [bytes([128, 128, 255] * w)] * h)


if __name__ == "__main__":
    sky()
    earth()
    flat_normal()
