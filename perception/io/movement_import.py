"""Importing the third-party ``movement`` package without side effects.

``movement`` reads and writes the pose files of other tools (see
:mod:`perception.io.pose`), but importing it is not quiet: ``movement``
creates ``~/.movement/movement.log``, adds a stderr handler and redirects the
process's warnings into that log, and ``pynwb``, which it imports, creates
``~/.cache/pynwb-hdmf/<version>``. A library must write nothing outside the
output folder it is given, nor need a writable HOME, so :func:`import_movement`
imports the package with its logging set-up skipped (an import hook,
:class:`_QuietMovementLogging`), ``platformdirs`` told not to create folders,
and ``movement``'s ``loguru`` messages disabled. :func:`movement_loaders`
gives its loaders, or one :class:`~perception.errors.InputError` naming the
optional extra when ``movement`` is not installed.
"""

from __future__ import annotations

import importlib.abc
import sys

from perception.errors import InputError

__all__ = ["POSE_EXTRA", "import_movement", "movement_loaders"]

#: The message when the optional ``pose`` extra (``movement``, PyTables) is missing.
POSE_EXTRA = ("reading and writing pose files needs the optional extra: "
              "pip install 'hammer-mv[pose]'")


class _QuietMovementLogging(importlib.abc.MetaPathFinder):
    """Import hook: ``movement.utils.logging`` loads with a ``configure`` that does nothing.

    Importing ``movement`` calls ``logger.configure()``, which creates
    ``~/.movement/movement.log`` (failing with a read-only or missing HOME),
    adds a stderr handler and redirects every warning of the process into its
    log. Only while :func:`import_movement` imports the package, the module
    is loaded as usual and its ``MovementLogger.configure`` replaced before
    ``movement/__init__`` calls it; the original is put back afterwards, so a
    user calling it on purpose gets movement's logging as documented.
    """

    def __init__(self):
        self.original = None

    def find_spec(self, name, path=None, target=None):
        if name != "movement.utils.logging":
            return None
        for finder in sys.meta_path:
            if finder is self or not hasattr(finder, "find_spec"):
                continue
            spec = finder.find_spec(name, path, target)
            if spec is not None and spec.loader is not None:
                break
        else:
            return None
        hook, loader = self, spec.loader
        real_exec = loader.exec_module

        def exec_module(module):
            real_exec(module)
            hook.original = module.MovementLogger.configure
            module.MovementLogger.configure = lambda self, *args, **kwargs: None

        spec.loader = _ExecWrapper(loader, exec_module)
        return spec


class _ExecWrapper(importlib.abc.Loader):
    def __init__(self, loader, exec_module):
        self._loader, self._exec = loader, exec_module

    def create_module(self, spec):
        return self._loader.create_module(spec)

    def exec_module(self, module):
        self._exec(module)

    def __getattr__(self, name):
        return getattr(self._loader, name)


def import_movement() -> None:
    """Import ``movement`` without writing under HOME (see :class:`_QuietMovementLogging`).

    Its own messages are disabled in ``loguru`` (the package's loaders log
    every file they read); a user enables them with
    ``loguru.logger.enable("movement")``.
    """
    if "movement.io" in sys.modules:
        return
    hook = _QuietMovementLogging()
    sys.meta_path.insert(0, hook)
    dirs = None
    if "pynwb" not in sys.modules:
        # pynwb (imported by movement.io) creates ~/.cache/pynwb-hdmf/<version>
        # at import for a cache of its schema: while it is imported, its
        # folders are not created (its cache is then skipped if absent)
        import platformdirs

        dirs = platformdirs.PlatformDirs

        class _NoCreate(dirs):
            def __init__(self, *args, **kwargs):
                kwargs["ensure_exists"] = False
                super().__init__(*args, **kwargs)

        platformdirs.PlatformDirs = _NoCreate
    try:
        import movement.io  # noqa: F401
    finally:
        sys.meta_path.remove(hook)
        if hook.original is not None:
            sys.modules["movement.utils.logging"].MovementLogger.configure = hook.original
        if dirs is not None:
            import platformdirs

            platformdirs.PlatformDirs = dirs
    from loguru import logger

    logger.disable("movement")


def movement_loaders():
    """``movement``'s ``load_dataset`` and ``load_poses``, or a one-line error naming the extra."""
    try:
        import_movement()
        from movement.io import load_dataset, load_poses
    except ImportError:
        raise InputError(POSE_EXTRA) from None
    return load_dataset, load_poses
