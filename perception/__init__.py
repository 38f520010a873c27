"""perception: video -> tracks -> observations -> HAMMER-MV recognition -> reports.

The public names (:mod:`perception.api`) are importable from here::

    from perception import track_video, Tracks, observe, Repertoire, recognize_clip

They are loaded on first use (``lazy_loader``, from the names
``__init__.pyi`` lists, which IDEs, type checkers and ``help(perception)``
read too), so importing one topic module (say :mod:`perception.io.tracks`)
does not pull in OpenCV, matplotlib and the rest.

A public name that is also a submodule's (``landmarks``, the function of
:mod:`perception.measure`; :mod:`perception.landmarks` the module) stays the
public name when the submodule is imported: import the module's contents
with ``from perception.landmarks import ...``.
"""

import sys as _sys
import types as _types
from pathlib import Path as _Path

import lazy_loader as _lazy

from minvar import __version__ as __version__

__getattr__, __dir__, __all__ = _lazy.attach_stub(__name__, __file__)

#: Public names that a submodule of the same name would replace when it is first imported.
_SHADOWED = frozenset(n for n in __all__ if (_Path(__file__).parent / f"{n}.py").is_file()
                      or (_Path(__file__).parent / n / "__init__.py").is_file())


class _PublicNames(_types.ModuleType):
    """The package, whose public names its submodules of the same name do not replace.

    Importing a submodule sets it as an attribute of its package; for
    ``landmarks`` that would turn ``perception.landmarks`` (the function) into
    the module after any import of :mod:`perception.landmarks`.
    """

    def __setattr__(self, name, value):
        if name in _SHADOWED and value is _sys.modules.get(f"{self.__name__}.{name}"):
            self.__dict__.pop(name, None)  # leave the name to __getattr__: the public one
            return
        super().__setattr__(name, value)


_sys.modules[__name__].__class__ = _PublicNames
