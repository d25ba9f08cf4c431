#!/usr/bin/env python3
"""Pixels that differ between consecutive images, for scripts/bench/shots.sh.

    python3 scripts/bench/pixdiff.py A.png B.png [C.png ...]

Prints one line per pair (A B, B C, ...): the later file, the pixels whose 8-bit colour
differs, and their share of the image. Reads 8-bit RGB or RGBA PNGs with zlib alone, so
that it needs no imaging library.
"""
import struct
import sys
import zlib


def paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


def pixels(path):
    """The pixels of the PNG at `path`, row by row, as bytes objects of 3 or 4 bytes."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit("%s: not a PNG" % path)
    pos, idat = 8, []
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour not in (2, 6) or interlace:
                sys.exit("%s: not an 8-bit RGB or RGBA PNG without interlace" % path)
            bpp = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat.append(body)
        pos += 12 + n
    raw = zlib.decompress(b"".join(idat))
    stride = width * bpp
    rows, above = [], bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind, row = raw[start], bytearray(raw[start + 1:start + 1 + stride])
        for i in range(stride):
            left = row[i - bpp] if i >= bpp else 0
            corner = above[i - bpp] if i >= bpp else 0
            if kind == 1:
                row[i] = (row[i] + left) & 255
            elif kind == 2:
                row[i] = (row[i] + above[i]) & 255
            elif kind == 3:
                row[i] = (row[i] + (left + above[i]) // 2) & 255
            elif kind == 4:
                row[i] = (row[i] + paeth(left, above[i], corner)) & 255
        rows.append(bytes(row))
        above = row
    flat = b"".join(rows)
    return [flat[i:i + bpp] for i in range(0, len(flat), bpp)]


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: pixdiff.py A.png B.png [C.png ...]")
    before = pixels(sys.argv[1])
    for path in sys.argv[2:]:
        now = pixels(path)
        if len(now) != len(before):
            sys.exit("%s: not the size of the image before it" % path)
        differ = sum(1 for a, b in zip(before, now) if a != b)
        print("%s %d %.3f" % (path, differ, 100.0 * differ / len(now)))
        before = now


if __name__ == "__main__":
    main()
