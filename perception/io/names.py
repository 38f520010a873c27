"""Clip names made safe to name files and to show.

A clip name comes from the outside world: a file name (which on POSIX may
hold bytes that are not UTF-8, given by Python as surrogate escapes), a
manifest row or a caller. :func:`output_stem` turns it into the stem of the
clip's output files: valid UTF-8, no separator or control character, and
short enough that every output name — and the temporary name it is written
under (:func:`perception.io.atomic.atomic_path`) — fits the 255 bytes a file
name may have. Two clip names never share a stem: a name that has to be
changed gets a short hash of its original bytes. :func:`printable` is the
name as shown in a page, a table or a figure: what cannot be shown as text
is escaped (``\\xff`` for an undecodable byte, ``\\n`` for a newline).
:func:`output_folder` is a subfolder of an output folder that cannot lead
out of it through a symbolic link.
"""

from __future__ import annotations

import hashlib
import os
import re
from pathlib import Path

from perception.errors import InputError

#: Video file extensions (case-insensitive).
VIDEO_SUFFIXES = (".mp4", ".avi", ".mkv", ".mov", ".m4v")
#: Name ending of a tracks file.
TRACKS_SUFFIX = ".tracks.h5"
#: Endings of pose files (a ``.h5`` that is not a tracks file is read as one).
POSE_SUFFIXES = (".h5", ".csv", ".slp", ".nc", ".nwb")


def live_kind(spec: str) -> str | None:
    """``camera`` (an index such as ``0``), ``stream`` (a URL) or None (a file): the one test
    of a live source, for the registry (:mod:`perception.sources`) and the capture that
    opens it.

    Parameters
    ----------
    spec : str
        The input as the user gave it.
    """
    spec = str(spec)
    return "camera" if re.fullmatch(r"\d+", spec) else "stream" if "://" in spec else None

__all__ = ["NAME_MAX", "POSE_SUFFIXES", "STEM_MAX", "TRACKS_SUFFIX", "VIDEO_SUFFIXES",
           "live_kind", "output_folder", "output_stem", "printable"]

#: The longest file name (bytes) on the usual file systems (ext4, XFS, APFS, NTFS).
NAME_MAX = 255
#: The longest stem :func:`output_stem` gives (bytes): leaves room for the
#: longest suffix an output adds (``.recognition.json``, a step's own
#: ``.<name>.png``).
STEM_MAX = 200
#: Characters never put in a file name: surrogates (undecodable bytes), path
#: separators, control characters.
_UNSAFE = re.compile(r"[\ud800-\udfff/\\\x00-\x1f\x7f]")
#: Characters shown escaped: surrogates and control characters.
_UNPRINTABLE = re.compile(r"[\ud800-\udfff\x00-\x1f\x7f-\x9f]")
_ESCAPES = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}


def _raw(name: str) -> bytes:
    """The name's bytes (its original bytes for a surrogate-escaped file name)."""
    return name.encode("utf-8", "surrogateescape" if _only_escapes(name) else "surrogatepass")


def _only_escapes(name: str) -> bool:
    return all(not 0xD800 <= ord(c) <= 0xDFFF or 0xDC80 <= ord(c) <= 0xDCFF for c in name)


def _cut(text: str, limit: int) -> str:
    """The longest start of ``text`` whose UTF-8 form has at most ``limit`` bytes."""
    return text.encode("utf-8")[:limit].decode("utf-8", "ignore")


def output_stem(clip: str, limit: int = STEM_MAX) -> str:
    """The stem of ``clip``'s output files: ``clip`` itself when it can name files as it is.

    A name with a character that cannot be in a file name as UTF-8 text
    (a byte that was not UTF-8, a separator, a control character) has it
    replaced by ``_``; a name longer than ``limit`` bytes is cut short. A
    name changed either way ends in ``~`` and ten hex digits of a hash of
    its original bytes, so two clips never share a stem.

    Parameters
    ----------
    clip : str
        The clip name (possibly surrogate-escaped, from :func:`os.fsdecode`).
    limit : int
        The longest stem, bytes of UTF-8.

    Returns
    -------
    str
        Valid UTF-8, at most ``limit`` bytes, no ``/`` or control character.
    """
    safe = _UNSAFE.sub("_", clip)
    if safe == clip and len(clip.encode("utf-8")) <= limit:
        return clip
    tag = "~" + hashlib.sha1(_raw(clip)).hexdigest()[:10]
    return _cut(safe, limit - len(tag)) + tag


def printable(text: str) -> str:
    """``text`` as it can be shown: undecodable bytes as ``\\xNN``, control characters escaped.

    Text without such characters is returned unchanged.

    Parameters
    ----------
    text : str
        A clip name, a path, a message.
    """
    if not _UNPRINTABLE.search(text):
        return text

    def escape(m: re.Match) -> str:
        c = m.group()
        code = ord(c)
        if 0xDC80 <= code <= 0xDCFF:  # a byte that was not UTF-8
            return f"\\x{code - 0xDC00:02x}"
        if c in _ESCAPES:
            return _ESCAPES[c]
        return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"

    return _UNPRINTABLE.sub(escape, text)


def output_folder(out: str | os.PathLike, name: str) -> Path:
    """``out/name``, refused if it is a symbolic link leading outside ``out``.

    A subfolder of an output folder (``tracks``) left as a link to another
    folder would have the outputs written there: outside the folder the
    user named.

    Parameters
    ----------
    out : str or os.PathLike
        The output folder.
    name : str
        The subfolder (one name, no separator).

    Raises
    ------
    InputError
        ``out/name`` is a link whose target is not inside ``out``, or exists
        and is not a folder.
    """
    folder = Path(out) / name
    if folder.is_symlink():
        target = Path(os.path.realpath(folder))
        root = Path(os.path.realpath(out))
        if target != root and root not in target.parents:
            raise InputError(f"is a symbolic link to {printable(str(target))}, outside the "
                             "output folder; remove it or choose another output folder",
                             printable(str(folder)))
    if folder.exists() and not folder.is_dir():
        raise InputError("exists and is not a folder", printable(str(folder)))
    return folder
