"""perception: video -> tracks -> observations -> HAMMER-MV recognition -> reports."""

from minvar import __version__

__all__ = ["__version__"]
