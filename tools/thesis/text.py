"""The thesis text: where it is found, and whether a quoted line holds the words."""

from __future__ import annotations

import os
import re
from pathlib import Path

#: Where the thesis text is looked for, after ``$HAMMER_MV_THESIS``: a ``shared/seed``
#: folder inside the checkout, then beside it.
_ROOT = Path(__file__).resolve().parents[2]
THESIS_CANDIDATES = tuple(base / "shared" / "seed" / "minimum-variance-thesis.txt"
                          for base in (_ROOT, _ROOT.parent))


def thesis_text() -> list[str] | None:
    """The thesis's lines (index 0 is line 1), or None where the text is not at hand.

    Looked for at ``$HAMMER_MV_THESIS``, then :data:`THESIS_CANDIDATES`.
    """
    env = os.environ.get("HAMMER_MV_THESIS")
    for path in ([Path(env)] if env else []) + list(THESIS_CANDIDATES):
        if path.is_file():
            return path.read_text(encoding="utf-8").splitlines()
    return None


def _plain(text: str) -> str:
    return re.sub(r"\s+", " ", re.sub(r"[*_$]", "", text)).strip().lower()


def quote_is_on_line(lines: list[str], line: int, quote: str) -> bool:
    """Whether ``quote`` is on ``line`` (1-based) of the thesis ``lines``.

    Case, runs of white space and markdown emphasis (``*``, ``_``, ``$``) are ignored.

    Parameters
    ----------
    lines : list of str
        From :func:`thesis_text`.
    line : int
        Line number, from 1.
    quote : str
        The words.
    """
    return 1 <= line <= len(lines) and bool(quote) and _plain(quote) in _plain(lines[line - 1])
