#!/usr/bin/env python3
"""Compares two binary PPM (P6) images of the same size, for bench/spd_bench.sh.

  image_diff.py A.ppm B.ppm [--side-by-side OUT.png [--width W]]

Prints the mean absolute difference per channel, in 8-bit codes (0..255), and the fraction of
pixels with a channel more than 8 codes off. With --side-by-side, writes A and B next to each other
(each scaled to W pixels wide by nearest neighbour, default 256) as a PNG.
"""
import struct
import sys
import zlib


def read_ppm(path):
    with open(path, "rb") as f:
        data = f.read()
    fields, i = [], 0
    while len(fields) < 4:
        while data[i:i + 1].isspace():
            i += 1
        if data[i:i + 1] == b"#":
            while data[i:i + 1] != b"\n":
                i += 1
            continue
        j = i
        while not data[j:j + 1].isspace():
            j += 1
        fields.append(data[i:j])
        i = j
    if fields[0] != b"P6" or fields[3] != b"255":
        raise SystemExit(f"image_diff: {path} is not an 8-bit binary PPM")
    width, height = int(fields[1]), int(fields[2])
    return width, height, data[i + 1:i + 1 + 3 * width * height]


def write_png(path, width, height, rgb):
    raw = b"".join(b"\x00" + rgb[y * width * 3:(y + 1) * width * 3] for y in range(height))

    def chunk(kind, payload):
        return (struct.pack(">I", len(payload)) + kind + payload +
                struct.pack(">I", zlib.crc32(kind + payload) & 0xFFFFFFFF))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" +
                chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def scaled(width, height, rgb, new_width):
    new_height = max(1, height * new_width // width)
    out = bytearray(3 * new_width * new_height)
    for y in range(new_height):
        sy = y * height // new_height
        for x in range(new_width):
            sx = x * width // new_width
            i = 3 * (sy * width + sx)
            o = 3 * (y * new_width + x)
            out[o:o + 3] = rgb[i:i + 3]
    return new_height, bytes(out)


def main():
    args = sys.argv[1:]
    if len(args) < 2:
        raise SystemExit(__doc__)
    wa, ha, a = read_ppm(args[0])
    wb, hb, b = read_ppm(args[1])
    if (wa, ha) != (wb, hb):
        raise SystemExit(f"image_diff: sizes differ: {wa}x{ha} and {wb}x{hb}")
    total = sum(abs(x - y) for x, y in zip(a, b))
    large = sum(1 for p in range(0, len(a), 3)
                if max(abs(a[p + k] - b[p + k]) for k in range(3)) > 8)
    print(f"{total / len(a):.2f} {large / (wa * ha):.4f}")
    if "--side-by-side" in args:
        out = args[args.index("--side-by-side") + 1]
        width = int(args[args.index("--width") + 1]) if "--width" in args else 256
        h, left = scaled(wa, ha, a, width)
        _, right = scaled(wb, hb, b, width)
        gap = 4
        row = 3 * (2 * width + gap)
        canvas = bytearray(b"\xff" * (row * h))
        for y in range(h):
            canvas[y * row:y * row + 3 * width] = left[3 * width * y:3 * width * (y + 1)]
            start = y * row + 3 * (width + gap)
            canvas[start:start + 3 * width] = right[3 * width * y:3 * width * (y + 1)]
        write_png(out, 2 * width + gap, h, bytes(canvas))


if __name__ == "__main__":
    main()
