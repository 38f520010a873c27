"""C3D files -> a trial, through ezc3d (an optional extra: ``pip install 'hammer-mv[mocap]'``).

ezc3d reads what a file holds; a file cut short (a copy that stopped, a
download that broke) is read as far as it goes, and ezc3d rewrites the frame
count it reports to match. The count the file's own header states is read
here from its first bytes, so that a short file is said to be short.
"""

from __future__ import annotations

import os
import struct
from collections.abc import Mapping
from pathlib import Path
from typing import NamedTuple

import numpy as np

from perception.errors import InputError
from perception.io.mocap_trial import (
    MocapTrial,
    assemble,
    header_rate,
    strip_subject,
    unique_name,
)

__all__ = ["read_c3d"]

_MOCAP_EXTRA = "reading C3D files needs ezc3d: pip install 'hammer-mv[mocap]'"
#: C3D point groups that hold modelled outputs (Vicon Plug-in Gait), not markers.
_C3D_MODELLED = ("ANGLES", "FORCES", "MOMENTS", "POWERS", "SCALARS", "REACTIONS")
#: The processor type byte of the parameter section: DEC (VAX) floats for 85, big-endian for
#: MIPS (86); Intel (84) otherwise.
_DEC, _BIG_ENDIAN = 85, 86


#: POINT:UNITS words other than mm, cm and m, as writers put them in a parameter of 4
#: characters (Peak Performance writes 'mete').
_UNIT_WORDS = {word[:k]: unit for word, unit in (("meters", "m"), ("metres", "m"),
                                                 ("millimeters", "mm"), ("millimetres", "mm"),
                                                 ("centimeters", "cm"), ("centimetres", "cm"))
               for k in (4, len(word))}


def _ezc3d_says(exc: BaseException) -> str:
    """What ezc3d's error says of a file, without its advice to ezc3d's own users (a flag
    to set in its API, an issue to open with it)."""
    text = str(exc).strip()
    if "MIPS processor" in text:
        return ("written for a MIPS (SGI) processor, which ezc3d, the C3D reader, does not "
                "read: save it again as a PC (Intel) C3D")
    text = text.replace(". If you want to ignore this error, set ignoreBadFormatting to true",
                        "")
    return f"ezc3d: {text}"


def _c3d_values(group: Mapping, name: str) -> list:
    """A C3D parameter's values as a list (empty when the parameter is absent)."""
    value = group.get(name, {}).get("value", [])
    return list(value) if isinstance(value, list | tuple) else list(np.atleast_1d(value))


def _labels(point: Mapping) -> list[str]:
    """POINT:LABELS, then LABELS2, LABELS3, ...: a parameter holds at most 255 labels."""
    labels = _c3d_values(point, "LABELS")
    more = 2
    while f"LABELS{more}" in point:
        labels += _c3d_values(point, f"LABELS{more}")
        more += 1
    return [str(x).strip() for x in labels]


class _Bytes(NamedTuple):
    """What the checks before ezc3d read of a C3D file: its header (the first 512 bytes),
    its size, and its parameter section (at most the 255 blocks its header can count)."""

    head: bytes
    size: int
    section: bytes


def _file_bytes(path: Path) -> _Bytes | None:
    """The header, size and parameter section of a C3D file, read once; None if it cannot
    be read or its header is too short."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(512)
            if len(head) < 24:
                return None
            fh.seek(max(head[0] - 1, 0) * 512)
            section = fh.read(255 * 512)
            size = fh.seek(0, os.SEEK_END)
    except OSError:
        return None
    return _Bytes(head, size, section)


def _stated_frames(raw: _Bytes) -> tuple[int, int] | None:
    """``(frames the header states, frames whose bytes the file holds)``, or None if unknown.

    The header gives the parameter block, the point and analog counts per
    frame, the first and last frame, the scale (negative: floats) and the
    block where the data start.
    """
    head, size = raw.head, raw.size
    kind = raw.section[3] if len(raw.section) > 3 else None
    order = ">" if kind == _BIG_ENDIAN else "<"
    points, analogs, first, last = struct.unpack(order + "HHHH", head[2:10])
    (data_start,) = struct.unpack(order + "H", head[16:18])
    word = head[12:16]
    if kind == _DEC:  # a VAX F float: its two 16-bit words swapped, and 4 times the value
        word = word[2:] + word[:2]  # (read as IEEE, its sign is a bit of the mantissa)
    (scale,) = struct.unpack(order + "f", word)
    stated = last - first + 1
    width = 4 if scale < 0 else 2  # bytes per value
    frame_bytes = (4 * points + analogs) * width
    if stated <= 0 or not frame_bytes or not data_start:
        return None
    held = max(size - (data_start - 1) * 512, 0) // frame_bytes
    return stated, held


def _negative_length(raw: _Bytes) -> tuple[str, int] | None:
    """The first group or parameter, walked as ezc3d walks them, whose description length
    byte is 128 or more, with that length: ezc3d reads the byte as signed and asks for
    4 GB less the length (12 GB held for c3d.org's BKINtechnologies.c3d), or None."""
    if not raw.head[0]:
        return None
    section = raw.section
    if len(section) < 4 or section[3] == _BIG_ENDIAN:  # refused by ezc3d before
        return None
    groups: dict[int, str] = {}
    pos = 4
    while pos + 4 <= len(section):
        chars, gid = struct.unpack_from("<bb", section, pos)
        if not chars:  # the end of the section
            return None
        at = pos + 2 + abs(chars)  # the offset to the next entry, from here
        name = section[pos + 2:at].decode("latin-1")
        (step,) = struct.unpack_from("<H", section, at) if at + 2 <= len(section) else (0,)
        end = at + 2
        if gid < 0:
            groups[-gid] = name
        elif end + 2 <= len(section):
            size, dims = struct.unpack_from("<bb", section, end)
            shape = section[end + 2:end + 2 + max(dims, 0)]
            end += 2 + max(dims, 0) + abs(size) * int(np.prod(list(shape), dtype=np.int64))
        if end >= len(section):
            return None
        if section[end] > 127:
            return (name if gid < 0 else f"{groups.get(gid, gid)}:{name}"), section[end]
        if not step:
            return None
        pos = at + step
    return None


def read_c3d(path: Path, source: str, rate, units) -> list[MocapTrial]:
    """A C3D file's marker points.

    Parameters
    ----------
    path : Path
        The file.
    source : str
        The file as the caller named it.
    rate, units
        As :func:`perception.io.mocap.read_mocap` takes them.
    """
    try:
        import ezc3d
    except ImportError:
        raise InputError(_MOCAP_EXTRA, path) from None
    raw = _file_bytes(path)
    if raw is not None and (long := _negative_length(raw)) is not None:
        raise InputError(f"not a readable C3D file (the description of {long[0]} is "
                         f"{long[1]} characters long by its length byte: ezc3d, the C3D "
                         "reader, reads a length over 127 as negative and would ask for "
                         "gigabytes of memory)", path)
    try:
        c3d = ezc3d.c3d(os.fspath(path))
    except (OSError, RuntimeError, ValueError, IndexError) as exc:
        raise InputError(f"not a readable C3D file ({_ezc3d_says(exc)})", path) from None
    point = c3d["parameters"]["POINT"]
    points = np.asarray(c3d["data"]["points"], dtype=float)[:3]  # (3, n_points, n_frames)
    residuals = np.asarray(c3d["data"]["meta_points"]["residuals"], dtype=float)
    notes: list[str] = []
    if not points.shape[1]:  # before the rate: a forces-only file states POINT:RATE 0
        raise InputError("no marker points: POINT:USED is 0 (the file holds other data only: "
                         "analog channels, forces or rotations)",
                         path, field="POINT:USED")
    counts = None if raw is None else _stated_frames(raw)
    if counts is not None and min(counts[1], points.shape[2]) < counts[0]:
        held = min(counts[1], points.shape[2])
        if held == 0:
            raise InputError(f"the file is cut short: its header states {counts[0]} frames "
                             "and it holds none", path, field="header")
        notes.append(f"the file is cut short: its header states {counts[0]} frames, it holds "
                     f"{held}: those {held} are read")
        points, residuals = points[:, :, :held], residuals[..., :held]
    labels = _labels(point)
    labels = [labels[i] if i < len(labels) and labels[i] else f"point{i + 1}"
              for i in range(points.shape[1])]
    modelled = {str(x).strip() for g in _C3D_MODELLED for x in _c3d_values(point, g)}
    own = _c3d_values(point, "RATE") or [c3d["header"]["points"]["frame_rate"]]
    rate, more = header_rate(rate, float(own[0]), path, "POINT:RATE")
    notes += more
    markers = {}
    renamed: dict[str, list[str]] = {}  # label -> the names its points are read as
    for i, label in enumerate(labels):
        if label in modelled:
            continue
        xyz = points[:, i, :].T.copy()
        lost = ~np.isfinite(residuals[0, i]) | (residuals[0, i] < 0) if residuals.size else False
        xyz[lost] = np.nan
        name = unique_name(label, markers)
        renamed.setdefault(label, []).append(name)
        markers[name] = xyz
    renamed = {k: v for k, v in renamed.items() if len(v) > 1 or v != [k]}
    if renamed:
        said = "; ".join(f"{k!r} as {', '.join(map(repr, v))}" for k, v in sorted(renamed.items()))
        notes.append(f"labels written more than once ({', '.join(map(repr, sorted(renamed)))}): "
                     f"read {said}, in the order of POINT:LABELS")
    modelled_read = sum(1 for label in labels if label in modelled)
    if modelled_read:
        notes.append(f"{modelled_read} modelled points (angles, forces, ...) not read")
    if not markers:
        raise InputError("no marker points", path, field="POINT:LABELS")
    # Vicon writes its labels Subject:Marker, as in its CSV export: read alike
    short, more = strip_subject(list(markers))
    markers, notes = dict(zip(short, markers.values())), notes + more
    first = int(c3d["header"]["points"].get("first_frame", 0))
    time = (first + np.arange(points.shape[2])) / rate
    stated = [str(u).strip() for u in _c3d_values(point, "UNITS") if str(u).strip()]
    own_units = None
    if stated:
        word = _UNIT_WORDS.get(stated[0].lower(), stated[0])
        if word != stated[0] and units is None:
            notes.append(f"POINT:UNITS {stated[0]!r} read as {word}")
        own_units = (word, "POINT:UNITS")
    return assemble(path, source, [("", time, markers, {})], rate, units, own_units, notes)
