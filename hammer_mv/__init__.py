"""hammer-mv, the application: the ``hammer-mv`` command over :mod:`minvar` and :mod:`perception`.

The libraries never import this package.
"""

from minvar import __version__

__all__ = ["__version__"]
