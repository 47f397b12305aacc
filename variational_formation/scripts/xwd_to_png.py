#!/usr/bin/python3
"""Converts an X window dump (xwd -root, 24/32-bit TrueColor) to PNG with matplotlib.

usage: xwd_to_png.py IN.xwd OUT.png
"""
import struct
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image  # noqa: E402
import numpy as np  # noqa: E402


def read_xwd(path):
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 100:
        raise ValueError(f"{path}: too short for an XWD file")
    fields = struct.unpack(">25I", data[:100])
    header_size, version, _fmt, depth, width, height = fields[:6]
    byte_order, bits_per_pixel, bytes_per_line = fields[7], fields[11], fields[12]
    red_mask, green_mask, blue_mask = fields[14:17]
    ncolors = fields[19]
    if version != 7 or bits_per_pixel not in (24, 32) or depth < 24:
        raise ValueError(f"{path}: only 24/32-bit XWD version 7 is supported "
                         f"(version {version}, {bits_per_pixel} bits per pixel, depth {depth})")
    start = header_size + 12 * ncolors
    size = bits_per_pixel // 8
    rows = np.frombuffer(data, dtype=np.uint8, count=height * bytes_per_line, offset=start)
    pixels = rows.reshape(height, bytes_per_line)[:, :width * size].reshape(height, width, size)
    pixels = pixels.astype(np.uint32)
    order = range(size) if byte_order == 0 else reversed(range(size))  # LSB or MSB first
    raw = np.zeros((height, width), dtype=np.uint32)
    for weight, k in enumerate(order):
        raw |= pixels[:, :, k] << np.uint32(8 * weight)

    def channel(mask):
        shift = (mask & -mask).bit_length() - 1
        return ((raw & mask) >> shift).astype(np.uint8)

    return np.dstack([channel(red_mask), channel(green_mask), channel(blue_mask)])


if __name__ == "__main__":
    if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        sys.exit(0)
    if len(sys.argv) != 3:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        sys.exit(2)
    try:
        image = read_xwd(sys.argv[1])
    except (OSError, ValueError) as e:
        print(f"xwd_to_png: error: {e}", file=sys.stderr)
        sys.exit(2)
    matplotlib.image.imsave(sys.argv[2], image)
