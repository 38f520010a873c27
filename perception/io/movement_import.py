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
``movement`` is not installed. :func:`dlc_inputs` reads a DeepLabCut table
through movement's own validator without importing ``movement.io`` (whose
other readers cost a start-up 1.3 s).
"""

from __future__ import annotations

import importlib
import importlib.util
import itertools
import sys
from pathlib import Path

from perception.errors import InputError

__all__ = ["DLC_KEY", "POSE_EXTRA", "VALIDATOR", "dlc_inputs", "import_movement",
           "movement_loaders", "require_movement"]

#: The message when the optional ``pose`` extra (``movement``, PyTables) is missing.
#: The pandas HDF key of a DeepLabCut ``.h5`` table (as DeepLabCut writes it): here, where
#: the pose reader and the exports both take it without loading each other.
DLC_KEY = "df_with_missing"
POSE_EXTRA = ("reading and writing pose files needs the optional extra: "
              "pip install 'hammer-mv[pose]'")


def import_movement(module: str = "movement.io") -> None:
    """Import ``movement`` (its ``module``) without writing under HOME.

    Its own messages are disabled in ``loguru`` (the package's loaders log
    every file they read); a user enables them with
    ``loguru.logger.enable("movement")``, and gets movement's log file by
    calling ``movement.utils.logging.logger.configure()``, as documented.

    Parameters
    ----------
    module : str
        What to import: ``movement.io`` (every loader, which imports pynwb,
        sleap_io and their dependencies: about 1.3 s), or only
        ``movement.validators.datasets`` (xarray), which is all a DeepLabCut
        table needs (:func:`dlc_inputs`).

    Raises
    ------
    ImportError
        ``movement`` is not installed.
    """
    if module in sys.modules:
        return
    if "movement" in sys.modules:  # its __init__ (which configures the log) has run
        _import_quietly(module)
    else:
        _import_package(module)
    from loguru import logger

    logger.disable("movement")


def _import_package(module: str) -> None:
    """Import ``module`` and so the package, its ``logger.configure()`` doing nothing."""
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
    try:
        _import_quietly(module)
    except BaseException:
        sys.modules.pop(name, None)
        raise
    finally:
        logging.MovementLogger.configure = configure
    importlib.import_module("movement.utils").logging = logging  # as an import would


def _import_quietly(module: str) -> None:
    """Import ``module`` of movement, creating no folder and loading no OpenCV."""
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
        importlib.import_module(module)
    finally:
        platformdirs.PlatformDirs = dirs
        if hide_cv2:
            del sys.modules["cv2"]


def dlc_inputs(df, fps: float | None, source_software: str = "DeepLabCut"):
    """A DeepLabCut table as movement's validated poses inputs, without ``movement.io``.

    What ``movement.io.load_poses.from_dlc_style_df`` does (movement 0.15,
    pinned), through the same validator (``ValidPosesInputs``) and so with
    the same errors, up to the dataset (its ``to_dataset()``, which
    :class:`~perception.io.pose_arrays.PoseTable` stands in for), but without
    importing ``movement.io``, whose readers of other formats (pynwb,
    sleap_io, and what they pull in) cost about 0.65 s of a start-up (issue 45).

    Parameters
    ----------
    df : pandas.DataFrame
        Columns a MultiIndex of scorer, (individuals,) bodyparts and coords,
        as DeepLabCut writes them.
    fps : float, optional
        Frame rate; None: time in frames.
    source_software : str
        Recorded in the dataset's attributes.

    Raises
    ------
    InputError
        ``movement`` is not installed.
    """
    require_movement(VALIDATOR)
    from movement.validators.datasets import ValidPosesInputs

    if "individuals" in df.columns.names:
        individual_names = df.columns.get_level_values("individuals").unique().to_list()
    else:
        individual_names = ["individual_0"]
    keypoint_names = df.columns.get_level_values("bodyparts").unique().to_list()
    coord_names = df.columns.get_level_values("coords").unique().to_list()
    n_coords = len(coord_names)
    values = df.to_numpy()
    shape = (len(df), len(individual_names), len(keypoint_names), n_coords)
    where = [tuple(df.columns.get_level_values(level)) if level in df.columns.names
             else ("individual_0",) * df.shape[1]
             for level in ("individuals", "bodyparts", "coords")]
    held = list(zip(*where))
    coords_of: dict[tuple, set] = {}
    for who, part, coord in held:
        coords_of.setdefault((who, part), set()).add(coord)
    if held == list(itertools.product(individual_names, keypoint_names, coord_names)) or any(
            got != set(coord_names) for got in coords_of.values()):
        # every keypoint of every individual in order; or a keypoint short of a coordinate:
        # a damaged table, refused as movement refuses it (the values do not fill the shape)
        tracks = values.reshape((-1, *shape[1:]))
    else:
        import numpy as np

        # A multi-animal project's unique body parts (individual "single": the object, often)
        # are not kept for every animal, nor the animals' for it: each column is put in its
        # place and the keypoints an individual lacks are NaN (movement 0.15 reshapes the
        # table as if every individual had every keypoint, and reads it as garbage)
        tracks = np.full(shape, np.nan, dtype=values.dtype if values.dtype == object else float)
        at = [{name: i for i, name in enumerate(names)}
              for names in (individual_names, keypoint_names, coord_names)]
        for j, (who, part, coord) in enumerate(held):
            tracks[:, at[0][who], at[1][part], at[2][coord]] = values[:, j]
    tracks = tracks.transpose(0, 3, 2, 1)
    if "likelihood" in coord_names:  # x, y, likelihood
        likelihood_index = coord_names.index("likelihood")
        confidence_array = tracks[:, likelihood_index, :, :]
        position_array = tracks[:, [j for j in range(n_coords) if j != likelihood_index], :, :]
    else:  # x, y, z
        position_array, confidence_array = tracks, None
    return ValidPosesInputs(position_array=position_array, confidence_array=confidence_array,
                            individual_names=individual_names, keypoint_names=keypoint_names,
                            fps=fps, source_software=source_software)


#: The module of movement a DeepLabCut table needs (:func:`dlc_inputs`).
VALIDATOR = "movement.validators.datasets"


def require_movement(module: str = "movement.io") -> None:
    """:func:`import_movement`, or a one-line error naming the extra.

    Parameters
    ----------
    module : str
        ``movement.io``, or ``movement.validators.datasets`` for a DeepLabCut table.
    """
    try:
        import_movement(module)
    except ImportError:
        raise InputError(POSE_EXTRA) from None


def movement_loaders():
    """``movement``'s ``load_dataset`` and ``load_poses``, or a one-line error naming the extra."""
    require_movement()
    from movement.io import load_dataset, load_poses

    return load_dataset, load_poses
