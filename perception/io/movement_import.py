"""Importing the third-party ``movement`` package without side effects.

``movement`` reads and writes the pose files of other tools (see
:mod:`perception.io.pose`), but importing it is not quiet: its
``__init__`` calls ``logger.configure()``, which creates
``~/.movement/movement.log``, adds a stderr handler and redirects the
process's warnings into that log, and ``pynwb``, which it imports, creates
``~/.cache/pynwb-hdmf/<version>``. A library must write nothing outside the
output folder it is given, nor need a writable HOME. movement (0.15, and its
main branch as of 2026-08) offers no setting to skip that, so
:func:`import_movement` loads ``movement.utils.logging`` (stdlib and loguru
only) before the package, with ``configure`` doing nothing while the package
imports, and tells ``platformdirs`` not to create folders meanwhile. This
leans on that module's layout: pyproject.toml pins ``movement<0.16``.
:func:`movement_loaders` gives its loaders, or one
:class:`~perception.errors.InputError` naming the optional extra when
``movement`` is not installed.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path

from perception.errors import InputError

__all__ = ["POSE_EXTRA", "import_movement", "movement_loaders"]

#: The message when the optional ``pose`` extra (``movement``, PyTables) is missing.
POSE_EXTRA = ("reading and writing pose files needs the optional extra: "
              "pip install 'hammer-mv[pose]'")


def import_movement() -> None:
    """Import ``movement`` without writing under HOME.

    Its own messages are disabled in ``loguru`` (the package's loaders log
    every file they read); a user enables them with
    ``loguru.logger.enable("movement")``, and gets movement's log file by
    calling ``movement.utils.logging.logger.configure()``, as documented.

    Raises
    ------
    ImportError
        ``movement`` is not installed.
    """
    if "movement.io" in sys.modules:
        return
    package = importlib.util.find_spec("movement")  # found, not imported
    if package is None:
        raise ImportError("movement")
    name = "movement.utils.logging"
    spec = importlib.util.spec_from_file_location(
        name, Path(package.submodule_search_locations[0]) / "utils" / "logging.py")
    logging = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(logging)
    configure = logging.MovementLogger.configure
    logging.MovementLogger.configure = lambda self, *args, **kwargs: None
    sys.modules[name] = logging
    import platformdirs

    dirs = platformdirs.PlatformDirs

    class _NoCreate(dirs):  # pynwb's cache folder, made at its import: skipped if absent
        def __init__(self, *args, **kwargs):
            kwargs["ensure_exists"] = False
            super().__init__(*args, **kwargs)

    platformdirs.PlatformDirs = _NoCreate
    # sleap_io (movement's SLEAP reader) imports OpenCV if it can; a pose file needs none
    hide_cv2 = "cv2" not in sys.modules
    if hide_cv2:
        sys.modules["cv2"] = None  # import cv2 raises ImportError, which sleap_io allows
    try:
        importlib.import_module("movement.io")
    except BaseException:
        sys.modules.pop(name, None)
        raise
    finally:
        logging.MovementLogger.configure = configure
        platformdirs.PlatformDirs = dirs
        if hide_cv2:
            del sys.modules["cv2"]
    importlib.import_module("movement.utils").logging = logging  # as an import would
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
