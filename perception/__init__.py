"""perception: video -> tracks -> observations -> HAMMER-MV recognition -> reports.

The public names (:mod:`perception.api`) are importable from here::

    from perception import track_video, Tracks, observe, Repertoire, recognize_clip

They are loaded on first use (``lazy_loader``, from the names
``__init__.pyi`` lists, which IDEs, type checkers and ``help(perception)``
read too), so importing one topic module (say :mod:`perception.io.tracks`)
does not pull in OpenCV, matplotlib and the rest.
"""

import lazy_loader as _lazy

from minvar import __version__ as __version__

__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)
