"""What is known of a video file before it is decoded, and how OpenCV is handed it.

Before a frame is decoded: the frame rate an AVI's own header states
(:func:`avi_header_rate`; FFmpeg reads a rate of 0 there as 25) and the
codec FourCC as text (:func:`fourcc_str`). Handing a file to OpenCV:
:func:`opencv_name`, a name it can open a file by (a name that is not valid
UTF-8 would crash the process), and :func:`quiet_native_stderr`, which keeps
what OpenCV and FFmpeg print straight to stderr out of our own reports.
"""

from __future__ import annotations

import contextlib
import os
import struct
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path


def fourcc_str(code: float) -> str:
    """The FourCC ``code`` (``CAP_PROP_FOURCC``) as text, e.g. ``"FMP4"`` ("" if none)."""
    n = int(code)
    text = "".join(chr((n >> (8 * i)) & 0xFF) for i in range(4))
    return text if text.isprintable() and n else ""


def avi_header_rate(path: Path) -> float | None:
    """The frame rate the AVI at ``path`` states in its header (0 if none); None if not an AVI.

    The rate of the first video stream header (``strh``: ``dwRate / dwScale``),
    else ``1e6 / dwMicroSecPerFrame`` of the main header, as FFmpeg reads it.
    """
    try:
        with open(path, "rb") as fh:
            head = fh.read(1 << 16)
    except OSError:
        return None
    if len(head) < 12 or head[:4] != b"RIFF" or head[8:12] != b"AVI ":
        return None
    usec = 0
    i = head.find(b"avih")
    if 0 <= i <= len(head) - 12:
        usec = struct.unpack_from("<I", head, i + 8)[0]
    i = head.find(b"strh")
    while 0 <= i <= len(head) - 36:
        if head[i + 8:i + 12] == b"vids":
            scale, rate = struct.unpack_from("<II", head, i + 28)
            if scale and rate:
                return rate / scale
            break
        i = head.find(b"strh", i + 4)
    return 1e6 / usec if usec else 0.0


def utf8_name(path: str | os.PathLike) -> bool:
    """Whether ``path`` is valid UTF-8 (the only names OpenCV takes without crashing)."""
    try:
        os.fspath(path).encode("utf-8")
    except UnicodeEncodeError:  # undecodable bytes of the file system, as surrogates
        return False
    return True


@contextlib.contextmanager
def opencv_name(path: str | os.PathLike) -> Iterator[str]:
    """A name OpenCV can open ``path`` by, valid while the block runs.

    OpenCV converts a path to UTF-8 and crashes the process (a segfault,
    not an exception) on a file name that is not valid UTF-8 — such names
    are legal on Linux. Those files are opened through a link with a plain
    name in a private temporary folder; FFmpeg keeps the file itself open
    once the capture is made, so the link can go when the block ends.
    """
    if utf8_name(path):
        yield os.fspath(path)
        return
    with tempfile.TemporaryDirectory(prefix="hammer-mv-") as tmp:
        link = Path(tmp) / f"video{Path(os.fsencode(path).decode('utf-8', 'replace')).suffix}"
        link.symlink_to(Path(path).resolve())
        yield os.fspath(link)


@contextlib.contextmanager
def quiet_native_stderr() -> Iterator[None]:
    """Silence what OpenCV and FFmpeg print straight to the process's stderr.

    Their messages about a file we then report ourselves ("tag ... is not
    found", "Could not open codec") would make a one-line error three lines.
    Only file descriptor 2 is redirected, and only for the block.
    """
    try:
        fd = sys.stderr.fileno()
    except (AttributeError, OSError, ValueError):  # no real stderr (e.g. captured)
        yield
        return
    sys.stderr.flush()
    saved = os.dup(fd)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), fd)
            yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)
