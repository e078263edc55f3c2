#!/usr/bin/env python3
"""Writes an 8-bit grey PNG in the Oxford row layout (or a plain one) for the bad-input tests.

Usage: write_scan_png.py OUT.png ROWS COLUMNS [--stamp-us T0] [--constant-encoder]
       [--zero-stamps] [--plain]
Rows: int64 LE stamp (us, T0 + 625 per row), uint16 LE encoder, 255, then bins. --plain
writes zeros only (no metadata), e.g. a transposed or narrow image. Standard library only.
"""
import struct
import sys
import zlib


def png(width, height, rows):
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    raw = zlib.compressobj(1)
    body = b"".join(raw.compress(b"\x00" + r) for r in rows) + raw.flush()
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)) +
            chunk(b"IDAT", body) + chunk(b"IEND", b""))


def main(argv):
    out, rows, cols = argv[1], int(argv[2]), int(argv[3])
    t0 = int(argv[argv.index("--stamp-us") + 1]) if "--stamp-us" in argv else 1547131046353776
    plain = "--plain" in argv

    def row(a):
        if plain:
            return bytes(cols)
        enc = 100 if "--constant-encoder" in argv else (13 + a * (5600 // max(rows, 1))) % 5600
        stamp = 0 if "--zero-stamps" in argv else t0 + 625 * a
        meta = struct.pack("<qH", stamp, enc) + b"\xff"
        return (meta + bytes((a * 7 + b * 3) % 256 for b in range(cols - len(meta))))[:cols]

    with open(out, "wb") as f:
        f.write(png(cols, rows, (row(a) for a in range(rows))))


if __name__ == "__main__":
    main(sys.argv)
