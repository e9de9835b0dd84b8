#!/usr/bin/env python3
"""solution.vtu written in pieces holds exactly what one piece holds.

The VTU writer builds deal.II's patches for at most Output/Cells per VTU
piece cells at a time and writes each batch as a <Piece> of the one file,
so that its memory is that of a piece, not of the mesh (1 kB per cell).
For each SCENE this runs it twice, with one piece (a limit above the cell
count) and with pieces of 97 cells, decodes both files (deal.II's inline
base64 zlib blocks) and requires: ceil(cells / 97) pieces, the same arrays
in every piece, and the pieces' arrays concatenated equal to the one
piece's, value for value (connectivity shifted by the points of the pieces
before it, offsets by their connectivity).

Usage: vtu_pieces.py PROGRAM SCENE...
"""

import base64
import math
import re
import struct
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
import zlib
from pathlib import Path

import numpy as np

TYPES = {"Float32": np.float32, "Float64": np.float64, "Int32": np.int32,
         "Int64": np.int64, "UInt8": np.uint8, "UInt32": np.uint32}


def decode(array):
    """The values of a DataArray: base64 of the block header (number of
    blocks, block size, last block size, compressed sizes), then base64 of
    the compressed blocks."""
    text = "".join(array.text.split())
    first = base64.b64decode(text[:8])
    n_blocks = struct.unpack("<I", first[:4])[0]
    header_bytes = 4 * (3 + n_blocks)
    header_chars = 4 * math.ceil(header_bytes / 3)
    header = struct.unpack("<%dI" % (3 + n_blocks),
                           base64.b64decode(text[:header_chars]))
    data = base64.b64decode(text[header_chars:])
    raw, at = b"", 0
    for size in header[3:]:
        raw += zlib.decompress(data[at:at + size])
        at += size
    return np.frombuffer(raw, dtype=TYPES[array.get("type")])


def pieces(path):
    # deal.II writes a comment with the date before the root element.
    root = ET.fromstring(re.sub(r"<!--.*?-->", "", Path(path).read_text(),
                                flags=re.S))
    result = []
    for piece in root.iter("Piece"):
        arrays = {}
        for array in piece.iter("DataArray"):
            name = array.get("Name") or "points"
            arrays[name] = decode(array)
        result.append((int(piece.get("NumberOfPoints")),
                       int(piece.get("NumberOfCells")), arrays))
    return result


def run(program, scene, cells_per_piece, work):
    text = Path(scene).read_text()
    text = re.sub(r"(?m)^\s*set (Write files|Pictures|Folder|Terminal)\b.*$",
                  "", text)
    # The copy lives elsewhere: the mesh file by its absolute path.
    text = re.sub(r"(?m)^(\s*set File\s*=\s*)(\S+)\s*$",
                  lambda m: m.group(1) + str((Path(scene).parent /
                                              m.group(2)).resolve()), text)
    folder = Path(work) / ("out%d" % cells_per_piece)
    text += ("\nsubsection Output\n  set Folder = %s\n  set Pictures = false\n"
             "  set Write files = true\n  set Cells per VTU piece = %d\nend\n"
             % (folder, cells_per_piece))
    prm = Path(work) / Path(scene).name
    prm.write_text(text)
    subprocess.run([str(Path(program).resolve()), str(prm)], check=True,
                   cwd=work, stdout=subprocess.DEVNULL)
    return pieces(folder / "solution.vtu")


def main():
    program, scenes = sys.argv[1], sys.argv[2:]
    for scene in scenes:
        with tempfile.TemporaryDirectory() as work:
            whole = run(program, scene, 10**9, work)
            split = run(program, scene, 97, work)
        assert len(whole) == 1, "one piece expected, got %d" % len(whole)
        n_points, n_cells, one = whole[0]
        expected = math.ceil(n_cells / 97)
        assert len(split) == expected, \
            "%s: %d pieces, expected %d" % (scene, len(split), expected)
        assert sum(p[1] for p in split) == n_cells, "cell counts differ"
        assert sum(p[0] for p in split) == n_points, "point counts differ"
        for name, values in one.items():
            parts, points, connections = [], 0, 0
            for piece_points, _, arrays in split:
                assert name in arrays, "%s: piece without '%s'" % (scene, name)
                part = arrays[name]
                if name == "connectivity":
                    part = part + points
                elif name == "offsets":
                    part = part + connections
                parts.append(part)
                points += piece_points
                connections += len(arrays["connectivity"])
            joined = np.concatenate(parts)
            assert joined.dtype == values.dtype and \
                np.array_equal(joined, values), \
                "%s: array '%s' differs between one piece and %d" % (
                    scene, name, len(split))
        print("PASS: %s: %d cells in %d pieces of 97 equal one piece "
              "(%d arrays)" % (Path(scene).name, n_cells, len(split),
                                len(one)))


if __name__ == "__main__":
    main()
