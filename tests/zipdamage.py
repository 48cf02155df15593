"""Damage every ZIP header of a file's bytes the way a broken or foreign writer would (tests of the ZIP readers)."""

from __future__ import annotations

import struct


def flag_every_member(data: bytearray, damage: str) -> bytearray:
    """Give every local and central header an unknown compression method (``"method"``: 99) or the encryption
    flag (``"encrypted"``), in place; returns ``data``."""
    for sig, at in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):  # the flag field's offset in each header
        i = data.find(sig)
        while i >= 0:
            if damage == "method":
                data[i + at + 2 : i + at + 4] = struct.pack("<H", 99)
            else:
                data[i + at : i + at + 2] = struct.pack("<H", 1)
            i = data.find(sig, i + 4)
    return data
