"""Mathcad data tables: the grid of numbers of a table component, from its binary item.

A component's ``<binaryContent>`` item (base64 of gzip) holds Mathcad's record of the
component, then the component's own data as an OLE compound file (``D0 CF 11 E0 ...``),
preceded by its length (u32). The data table's stream ``Contents`` holds, after its
formatting, the matrix as a block::

    [length: u32] [16-byte block id] [1, 1, element size 8, dimensions 2: u32 x 4]
    [first col, first row, last col, last row: u32 x 4] [count: u32]
    [count doubles, column by column]

The compound file is read by its own tables (FAT, mini FAT, directory), so that a stream
stored in pieces is read in order; every offset, chain and count is checked, and a table
whose layout differs from this one is reported, never guessed.
"""

from __future__ import annotations

import struct

from .plot import payload
from .symbols import Untranslatable

#: the class id (clsid-buddy of the component) of Mathcad's data table
TABLE_CLSID = "01350081-1122-11DB-9380-000D56C6051A"
_SIGNATURE = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1"
#: the id of the block holding the matrix in the table's Contents stream
_MATRIX = bytes.fromhex("00548cc93163d011a68d00a024cf05d1")
_END = 0xFFFFFFFE  # end of a chain
_MAX_CELLS = 1_000_000


def _bad(what: str) -> Untranslatable:
    return Untranslatable(f"a data table whose binary item is not as expected ({what})")


def grid(encoded: str) -> list[list[float]]:
    """The table's numbers by rows, from its binary item (base64 of gzip)."""
    data = payload(encoded, "a data table")
    at = data.find(_SIGNATURE)
    if at < 4:
        raise _bad("no OLE compound file")
    (size,) = struct.unpack_from("<I", data, at - 4)
    cfb = data[at : at + size]
    if len(cfb) != size:
        raise _bad("a compound file cut short")
    return _cells(_stream(cfb, "Contents"))


def _cells(s: bytes) -> list[list[float]]:
    at = s.find(_MATRIX)
    if at < 4 or len(s) < at + 52:
        raise _bad("no matrix block")
    (length,) = struct.unpack_from("<I", s, at - 4)
    head = struct.unpack_from("<9I", s, at + 16)
    if head[:4] != (1, 1, 8, 2):
        raise _bad(f"a matrix block of kind {head[:4]}")
    col0, row0, col1, row1, count = head[4:]
    rows, cols = row1 - row0 + 1, col1 - col0 + 1
    if not (0 < rows and 0 < cols and rows * cols == count <= _MAX_CELLS):
        raise _bad(f"a grid of {rows} x {cols} with {count} cells")
    if length != 52 + 8 * count or len(s) < at + length:
        raise _bad("a matrix block whose length does not match its cells")
    values = struct.unpack_from(f"<{count}d", s, at + 52)
    return [[values[c * rows + r] for c in range(cols)] for r in range(rows)]


def _stream(cfb: bytes, name: str) -> bytes:
    """The stream ``name`` of an OLE compound file (version 3 or 4)."""
    if len(cfb) < 512 or not cfb.startswith(_SIGNATURE):
        raise _bad("a compound file without its header")
    shift, mini_shift = struct.unpack_from("<HH", cfb, 0x1E)
    if shift not in (9, 12) or mini_shift != 6:
        raise _bad("sector sizes")
    sector, mini = 1 << shift, 1 << mini_shift
    n_fat, first_dir = struct.unpack_from("<II", cfb, 0x2C)
    cutoff, first_minifat, n_minifat = struct.unpack_from("<III", cfb, 0x38)
    difat = struct.unpack_from("<109I", cfb, 0x4C)
    if n_fat > 109:
        raise _bad("a FAT of more than 109 sectors")
    offset = 512 if shift == 9 else 4096

    def read_sector(i: int) -> bytes:
        start = offset + i * sector
        if i >= _END - 5 or start + sector > len(cfb):
            raise _bad(f"sector {i} beyond the file")
        return cfb[start : start + sector]

    fat_bytes = b"".join(read_sector(i) for i in difat[:n_fat])
    fat = struct.unpack(f"<{len(fat_bytes) // 4}I", fat_bytes)

    def chain(first: int, table, limit: int) -> list[int]:
        out, i = [], first
        while i != _END:
            if i >= len(table) or len(out) > limit:
                raise _bad("a broken sector chain")
            out.append(i)
            i = table[i]
        return out

    limit = len(cfb) // mini
    directory = b"".join(read_sector(i) for i in chain(first_dir, fat, limit))
    minifat_bytes = b"".join(read_sector(i) for i in chain(first_minifat, fat, limit))
    minifat = struct.unpack(f"<{len(minifat_bytes) // 4}I", minifat_bytes)
    entries = {}
    for k in range(len(directory) // 128):
        e = directory[k * 128 : (k + 1) * 128]
        length, kind = struct.unpack_from("<HB", e, 64)
        if kind == 0 or not 2 <= length <= 64:
            continue
        start, size = struct.unpack_from("<II", e, 116)
        entries[e[: length - 2].decode("utf-16-le", "replace")] = (kind, start, size)
    root = next((v for v in entries.values() if v[0] == 5), None)
    if name not in entries or root is None:
        raise _bad(f"no {name} stream")
    _, start, size = entries[name]
    if size >= cutoff:
        data = b"".join(read_sector(i) for i in chain(start, fat, limit))
    else:
        ministream = b"".join(read_sector(i) for i in chain(root[1], fat, limit))
        pieces = chain(start, minifat, limit)
        if any((i + 1) * mini > len(ministream) for i in pieces):
            raise _bad("a mini sector beyond the mini stream")
        data = b"".join(ministream[i * mini : (i + 1) * mini] for i in pieces)
    if len(data) < size:
        raise _bad(f"a {name} stream cut short")
    return data[:size]
