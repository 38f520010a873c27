"""perception: video -> tracks -> observations -> HAMMER-MV recognition -> reports.

The public names (:mod:`perception.api`) are importable from here::

    from perception import track_video, Tracks, observe, Repertoire, recognize_clip

They are loaded on first use, so importing one topic module (say
:mod:`perception.io.tracks`) does not pull in OpenCV, matplotlib and the rest.
"""

import importlib

from minvar import __version__

__all__ = ["__version__"]


def __getattr__(name: str):
    if name.startswith("_"):
        raise AttributeError(name)
    api = importlib.import_module("perception.api")  # lazy on purpose: start-up time
    if name in api.__all__:
        return getattr(api, name)
    raise AttributeError(f"module 'perception' has no attribute {name!r}")


def __dir__() -> list[str]:
    api = importlib.import_module("perception.api")
    return sorted({*globals(), *api.__all__})
