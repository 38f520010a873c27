"""The clips of a batch input: a folder of videos, tracks, pose and motion-capture files,
or a manifest naming them (and their condition, participant or any other factor).

:func:`find_clips` lists them as :class:`BatchItem` (a clip found as several
files counted once), :func:`expand_recordings` turns a motion-capture
recording into one item per reach.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import re
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from perception.errors import HammerMVError, InputError
from perception.io.files import input_file, is_regular_file
from perception.io.pose import pose_output
from perception.pipeline import clip_name
from perception.recordings import unknown_layout
from perception.sources import files_taken

if TYPE_CHECKING:
    from perception.pipeline import RecognitionSettings
    from perception.reaches import Reach

__all__ = ["COMPANION_NAMES", "ERRORS_LOG", "REPORT_SET", "BatchItem", "Discovery",
           "batch_file", "check_clip_name", "discover", "expand_recordings", "find_clips",
           "recording_items", "safe_clip_name", "stream_recordings"]

log = logging.getLogger(__name__)

#: Files that sit beside clips and are not inputs: ground truth, the synth
#: manifest, and what a batch writes (so a report folder can be its own input).
COMPANION_SUFFIXES = (".truth.h5", ".recognition.json", ".confidence.csv", ".tracking.png",
                      ".status.csv", ".trials.csv",
                      *(f".{name}.{fmt}" for name in ("confidence", "paths", "kinematics")
                        for fmt in ("png", "svg", "pdf")))
#: Which file stands for a clip found more than once: a pose file beside its
#: video is what the lab tracked it with; a tracks file beside a video stands
#: for it only when it is current (checked when the video is loaded), so the
#: video is the clip. A motion-capture recording stands for no other file.
_PREFERENCE = {"pose": 3, "video": 2, "tracks": 1, "unknown": 0}
#: Tracebacks of the clips that failed through a bug (not their input).
ERRORS_LOG = "errors.log"
#: The batch's figures, by stem; each in one of the figure formats (png, svg, pdf).
BATCH_FIGURES = ("aperture_profiles", "confidence_single", "confidence_all", "condition_profiles",
                 "kinematic_profiles", "landmark_strips")
#: What a batch writes beside its clips' reports: one run's set, never a mix (:func:`run_batch`).
REPORT_SET = ("summary.csv", "summary.units.json", "statistics.csv", "condition_profiles.csv",
              "report.html", "batch.json", "aperture_profiles.csv", "kinematic_profiles.csv",
              ERRORS_LOG, "landmarks.csv", "participant_means.csv", "landmark_statistics.csv",
              *(f"{stem}.{fmt}" for stem in BATCH_FIGURES for fmt in ("png", "svg", "pdf")))
#: Why a folder inside a batch's input folder is skipped.
SUBFOLDER = ("a folder: the files of the folder given are read, not those of its "
             "subfolders (a manifest.csv can name them)")
COMPANION_NAMES = ("manifest.csv", "README.md", "recipe.toml", "repertoire.h5", *REPORT_SET)
#: A clip name becomes file names in the report folder: no separators, no
#: leading dot, nothing that is not printable.
_CLIP_NAME = re.compile(r"[^/\\\x00-\x1f\x7f]+")


@dataclass(frozen=True)
class BatchItem:
    """One clip of a batch.

    Attributes
    ----------
    clip : str
        Clip name (file stem; the file name when two files share a stem).
    path : Path
        Video, tracks or pose file.
    kind : str
        ``video``, ``tracks``, ``pose`` or ``mocap`` (a manifest row may name
        a file of another kind: ``unknown``, recorded as a failure).
    condition : str or None
        Stimulus condition, when a manifest gives it.
    reach : int or None
        Which reach of a motion-capture recording (:func:`expand_recordings`):
        its index among the recording's reaches.
    factors : tuple of (str, str)
        The manifest's other columns for this clip (participant, session, any
        factor), in its order.
    trial : str or None
        The recording's trial it belongs to (:func:`expand_recordings`).
    unscored : (str, str) or None
        A trial or movement of a recording that gives no reach to score: its
        status and reason (:class:`~perception.reaches.Unscored`); its row
        says so, nothing is scored.
    trial_number : str or None
        A recording's trial's own id, as its trial column writes it (its
        1-based index in a file without one): :attr:`Reach.trial_number`.
    reach_number : int or None
        Which reach of its trial, from 1 (None for a trial that gives none).
    """

    clip: str
    path: Path
    kind: str
    condition: str | None = None
    reach: int | None = None
    factors: tuple[tuple[str, str], ...] = ()
    trial: str | None = None
    unscored: tuple[str, str] | None = None
    trial_number: str | None = None
    reach_number: int | None = None


def check_clip_name(name: str, where: str) -> str:
    """``name`` if it can name a clip's report files inside the report folder.

    Parameters
    ----------
    name : str
        The clip name (from a manifest or a file name).
    where : str
        Where it comes from, for the message.

    Raises
    ------
    InputError
        An empty name, one with a path separator or control character, one
        starting with a dot (``..`` included) or longer than 200 characters.
    """
    if (not name or len(name) > 200 or name.startswith(".")
            or not _CLIP_NAME.fullmatch(name)):
        raise InputError(f"clip name {name!r} cannot name report files (no path separators, "
                         "no leading dot, printable, at most 200 characters)", where)
    return name


def _from_manifest(source: Path) -> list[BatchItem]:
    import pandas as pd  # not at the top: a worker process never needs pandas

    try:
        man = pd.read_csv(source, dtype=str, keep_default_na=False)
    except (OSError, ValueError, pd.errors.ParserError) as exc:
        raise InputError(f"unreadable manifest: {exc}", source) from None
    if "clip" not in man.columns or "video" not in man.columns:
        raise InputError("manifest needs columns clip and video", source)
    rows: dict[str, int] = {}
    items = []
    for i, row in enumerate(man.itertuples(index=False), start=2):  # row 1: the header
        clip = check_clip_name(str(row.clip), f"{source} row {i}")
        if clip in rows:
            raise InputError(f"clip {clip!r} appears twice (rows {rows[clip]} and {i}); "
                             "clip names must be unique", source)
        rows[clip] = i
        path = (source.parent / str(row.video)).resolve()
        cond = str(getattr(row, "condition", "") or "") or None
        factors = tuple((c, str(v)) for c, v in zip(man.columns, row)
                        if c not in ("clip", "video", "condition"))
        items.append(BatchItem(clip, path, clip_name(path)[1], cond, factors=factors))
    return sorted(items, key=lambda i: i.clip)


def batch_file(path: Path) -> None:
    """Refuse a clip's file that a batch cannot read, in one line: missing, not a regular
    file, empty, or of no kind a batch reads (a manifest can name one; a folder's are
    skipped before), listing every kind it reads, recordings too.

    Parameters
    ----------
    path : Path
        The file a batch item names.
    """
    input_file(path, "clip", empty=False)
    if clip_name(path)[1] == "unknown":
        raise InputError(f"not a {files_taken('batch')}", path)


@dataclass(frozen=True)
class Discovery:
    """What a batch input holds.

    Attributes
    ----------
    items : list of BatchItem
        The clips, sorted by name.
    skipped : list of (str, str)
        Files of a folder that are not clips, with why: ``(file name, reason)``.
    """

    items: list[BatchItem]
    skipped: list[tuple[str, str]]


def discover(source: str | os.PathLike) -> list[BatchItem]:
    """List the clips of a batch input (:func:`find_clips`, without the skipped files).

    Parameters
    ----------
    source : str or os.PathLike
        A folder or a ``manifest.csv``.
    """
    return find_clips(source).items


def find_clips(source: str | os.PathLike) -> Discovery:
    """List the clips of a batch input, and the files of a folder that are not clips.

    Parameters
    ----------
    source : str or os.PathLike
        A folder, or a ``manifest.csv`` with columns ``clip``, ``condition`` and
        ``video`` (path relative to the manifest) as written by ``hammer-mv synth``.

    Returns
    -------
    Discovery
        Clips sorted by name. A clip found as several files uses its pose
        file before its video (what the lab tracked it with), and its video
        before a tracks file of the same name: such tracks are reused only
        if they are current for that very video and these settings
        (:func:`~perception.pipeline.current_tracks`), as ``recognize`` does.
        Two files of equal standing with one stem (``dup.avi``, ``dup.mp4``)
        are both clips, named by their file names. What DeepLabCut and SLEAP
        write beside a video is that video's clip (``trial01DLC_….h5``:
        ``trial01``), read from its best pose file
        (:func:`~perception.io.pose.pose_output`). Files that are not clips
        (notes, setups, labelled videos, metadata, the other pose files of a
        clip, FIFOs, devices or links to them) are skipped, never opened; so
        are subfolders (their files are not read), but for a batch report's.

    Raises
    ------
    InputError
        If the source does not exist, a manifest is unreadable, or a manifest's
        clip names are not unique or would name files outside the report folder.
    """
    source = Path(source)
    if not source.exists():
        raise InputError("batch input not found", source)
    if not source.is_dir():
        if source.suffix.lower() != ".csv":
            raise InputError("batch input must be a folder or a manifest.csv", source)
        return Discovery(_from_manifest(input_file(source, "manifest")), [])
    listed = {}
    manifest = source / "manifest.csv"
    if is_regular_file(manifest):
        listed = {i.clip: i for i in _from_manifest(manifest)}
    by_stem: dict[str, list[BatchItem]] = {}
    skipped = []
    rank: dict[Path, int] = {}  # of the pose files DeepLabCut or SLEAP wrote for one video
    # a report folder may be its own input: its batch's files are not the user's
    report_folder = (source / "batch.json").is_file()
    for path in sorted(source.iterdir()):
        if path.name in REPORT_SET and not report_folder and not path.is_dir():
            skipped.append((path.name, "a name the batch report writes: not read as a clip"))
            continue
        if path.name.startswith(".") or path.name in COMPANION_NAMES:
            continue
        if path.is_dir():
            # a batch report (this input's own tracks/, or a report folder inside it) holds
            # no clips; any other folder is named, never passed over without a word
            if not (report_folder or (path / "batch.json").is_file()):
                skipped.append((path.name, SUBFOLDER))
            continue
        if path.name.endswith(COMPANION_SUFFIXES):
            continue
        clip, kind = clip_name(path)
        output = pose_output(path.name)
        if output is not None and isinstance(output[1], str):  # a labelled video, metadata
            skipped.append((path.name, output[1]))
        elif is_regular_file(path) and (why := unknown_layout(path)) is not None:
            skipped.append((path.name, why))
        elif kind == "unknown":
            skipped.append((path.name, "empty file (0 bytes)" if is_regular_file(path)
                            and path.stat().st_size == 0 else f"not a {files_taken('batch')}"))
        elif not is_regular_file(path):
            skipped.append((path.name, "not a regular file (a FIFO, device, socket or a "
                                       "broken link)"))
        else:
            rank[path] = output[1] if output is not None and kind == "pose" else 0
            row = listed.get(clip)
            by_stem.setdefault(clip, []).append(BatchItem(
                clip, path, kind, row.condition if row else None,
                factors=row.factors if row else ()))
    items = []
    for found in by_stem.values():
        # a recording is never another file's clip (a pose file is its video's): a table
        # and a video of one stem (P01.tsv, P01.mp4) are two clips, named by file name
        recordings = [i for i in found if i.kind == "mocap"]
        found = [i for i in found if i.kind != "mocap"]
        if recordings and (found or len(recordings) > 1):
            items += [dataclasses.replace(i, clip=i.path.name) for i in recordings]
            if found:
                found = [dataclasses.replace(i, clip=i.path.name) for i in found]
        elif recordings:
            items += recordings
        if not found:
            continue
        best = max((_PREFERENCE[i.kind], rank[i.path]) for i in found)
        chosen = [i for i in found if (_PREFERENCE[i.kind], rank[i.path]) == best]
        skipped += [(i.path.name, f"clip {i.clip!r} is read from {chosen[0].path.name}")
                    for i in found if i.kind == "pose" and i not in chosen]
        if len(chosen) > 1:  # the stem alone would not tell them apart
            chosen = [dataclasses.replace(i, clip=i.path.name) for i in chosen]
        items += chosen
    skipped.sort()
    for name, why in skipped:
        log.info("%s: skipped: %s", source / name, why)
    return Discovery(sorted(items, key=lambda i: i.clip), skipped)


def expand_recordings(items: Iterable[BatchItem], settings: RecognitionSettings
                      ) -> list[BatchItem]:
    """Each motion-capture recording as one item per reach in it, and one per trial or
    movement that gives none (other items as they are), each with its design's factors.

    A recording that cannot be read (or whose reading meets a bug) stays one
    item, which fails with its error when processed. A trial or movement that gives no reach is an
    item with its status and reason (:attr:`BatchItem.unscored`): the batch's
    row for it says why. A reach's name comes from its trial's: when that
    cannot name files (``x/../y``) it is made safe (:func:`safe_clip_name`);
    a recording named by its file name (two files of one stem) names its
    reaches so too (``P01.tsv-trial3``); a name taken twice gets ``~2``, ...

    Each item's factors are the manifest's, its trial's columns' and its
    file name's (``settings.mocap.factors_from_name``;
    :mod:`perception.factors`); a ``condition`` among them is the item's
    :attr:`BatchItem.condition`. A recording's reach carries its trial's
    number and its own (:attr:`BatchItem.trial_number`,
    :attr:`BatchItem.reach_number`).

    Parameters
    ----------
    items : iterable of BatchItem
        Clips (see :func:`discover`).
    settings : RecognitionSettings
        Their ``mocap`` settings say how recordings are read.

    Raises
    ------
    InputError
        A factor with one value in the manifest and another in a trial's
        columns or a file's name (or a bad ``factors_from_name``).
    """
    return [item for item, _ in recording_items(items, settings)]


def recording_items(items: Iterable[BatchItem], settings: RecognitionSettings
                    ) -> list[tuple[BatchItem, Reach | None]]:
    """:func:`expand_recordings`' items, each recording's reach with its samples (read
    here once: a batch hands them to its workers, which then read no file).

    :func:`stream_recordings` run to the end: a recording found at its end to
    give nothing is one item, in the place of the trials it had given.

    Parameters
    ----------
    items : iterable of BatchItem
        Clips (see :func:`discover`).
    settings : RecognitionSettings
        Their ``mocap`` settings say how recordings are read.
    """
    failed: list[tuple[BatchItem, list[str]]] = []
    out = list(stream_recordings(items, settings, failed))
    taken = {name: whole for whole, names in failed for name in names}
    if not taken:
        return out
    kept, placed = [], set()
    for item, reach in out:
        whole = taken.get(item.clip)
        if whole is None:
            kept.append((item, reach))
        elif whole.clip not in placed:
            placed.add(whole.clip)
            kept.append((whole, None))
    return kept


def stream_recordings(items: Iterable[BatchItem], settings: RecognitionSettings,
                      failed: list[tuple[BatchItem, list[str]]]
                      ) -> Iterator[tuple[BatchItem, Reach | None]]:
    """:func:`expand_recordings`' items one trial at a time, as each is read, each reach
    with its samples: a batch hands them out while it reads the rest.

    Names are made unique as they come, in the same order, so the items are
    :func:`expand_recordings`' while every recording reads to its end. One that
    cannot be read at all is one item (it fails where it runs), as there; one
    found at its end to give nothing (a marker never seen in any trial) has
    had its trials handed out already: it is appended to ``failed`` with the
    names of the items given for it, for its caller to take back.

    Parameters
    ----------
    items : iterable of BatchItem
        Clips (see :func:`discover`).
    settings : RecognitionSettings
        Their ``mocap`` settings say how recordings are read.
    failed : list
        Where a recording that fails at its end goes, as ``(item, names)``.

    Yields
    ------
    (BatchItem, Reach or None)
        Each item, with its reach for a recording's reach.

    Raises
    ------
    InputError
        As :func:`expand_recordings` (a factor given two values), once the
        trial that says so is read.
    """
    from perception.recordings import MocapImport

    mocap = getattr(settings, "mocap", None) or MocapImport()
    seen: set[str] = set()
    for item in items:
        if not _a_recording(item):
            yield _unique(_as_given(item, mocap), seen), None
            continue
        fault: list[BaseException] = []
        given: list[str] = []
        for new, reach in _recording_items(item, _read(item.path, settings.mocap, fault)):
            new = _unique(new, seen)
            given.append(new.clip)
            yield new, reach
        if fault:  # as expand_recordings: one item, which fails where it runs
            whole = _unique(_with_factors(item, mocap.name_factors(item.path)), seen)
            if given:
                failed.append((whole, given))
            else:
                yield whole, None


def _read(path: Path, options, fault: list[BaseException]):
    """:func:`~perception.recordings.iter_recording`, its failure put in ``fault``."""
    from perception.recordings import iter_recording

    try:
        yield from iter_recording(path, options)
    except (HammerMVError, OSError) as exc:
        fault.append(exc)
    except Exception as exc:  # noqa: BLE001 - a bug reading one file must not end the batch
        log.debug("%s: unreadable (a bug); it fails when processed", path, exc_info=True)
        fault.append(exc)


def _a_recording(item: BatchItem) -> bool:
    """Whether ``item`` is a motion-capture recording still to be read into reaches."""
    return item.kind == "mocap" and item.reach is None and item.unscored is None


def _as_given(item: BatchItem, mocap) -> BatchItem:
    """An item that is not a recording to read, with the factors its file name gives."""
    return _with_factors(item, mocap.name_factors(item.path) if item.reach is None
                         and item.unscored is None else {})


def _recording_items(item: BatchItem, trials) -> Iterator[tuple[BatchItem, Reach | None]]:
    """A recording's items, from its trials' entries (``(trial name, entries)``, in
    order), each reach with its samples; names not yet unique."""
    from perception.reaches import Reach

    stem, k = item.path.stem, 0
    for trial, entries in trials:
        for entry in entries:
            name = entry.name
            if item.clip != stem and name.startswith(stem):  # named by its file's name
                name = item.clip + name[len(stem):]
            common = dict(clip=safe_clip_name(name, str(item.path)), path=item.path,
                          kind="mocap", condition=item.condition, factors=item.factors,
                          trial=trial, trial_number=entry.trial_number or None,
                          reach_number=entry.reach_number)
            if isinstance(entry, Reach):
                new = BatchItem(**common, reach=k)
                k += 1
            else:
                new = BatchItem(**common, unscored=(entry.status, entry.reason))
            yield (_with_factors(new, entry.factors,
                                 f"{item.path.name}'s trial columns or file name"),
                   entry if isinstance(entry, Reach) else None)


def _with_factors(item: BatchItem, found, source: str | None = None) -> BatchItem:
    """``item`` with the factors ``found`` for it besides the manifest's: a ``condition``
    among them is its condition, the others follow the manifest's columns."""
    if not found:
        return item
    from perception.factors import NAME_FLAG, merge_factors

    given = dict(item.factors)
    if item.condition is not None:
        given["condition"] = item.condition
    merged = merge_factors([("the manifest", given),
                            (source or f"its file name (`{NAME_FLAG}`)", found)], item.path)
    condition = merged.pop("condition", None)
    return dataclasses.replace(item, condition=condition or None,
                               factors=tuple(merged.items()))


def safe_clip_name(name: str, where: str) -> str:
    """``name`` if it can name a clip's report files, else a safe name made from it.

    A trial's name comes from inside a file (a table's trial column): one
    that cannot name files (``x/../y``, a leading dot) is given separators,
    control characters and a leading dot as ``_`` and a short hash of the
    original (:func:`~perception.io.names.output_stem`), so that one unsafe
    trial never ends a batch. The change is logged.

    Parameters
    ----------
    name : str
        The name.
    where : str
        Where it comes from, for the log.
    """
    import hashlib

    from perception.io.names import output_stem

    try:
        return check_clip_name(name, where)
    except InputError:
        safe = output_stem(name)
        if safe == name or safe.startswith("."):  # unchanged there: a dot first, or empty
            tag = "~" + hashlib.sha1(name.encode("utf-8", "surrogatepass")).hexdigest()[:10]
            safe = "_" + output_stem(name).lstrip(".")[:180].split("~")[0] + tag
        log.warning("%s: trial %r named %r in the report", where, name, safe)
        return safe


def _unique(item: BatchItem, seen: set[str]) -> BatchItem:
    """``item`` with a name none of ``seen`` has (``~2``, ``~3``, ...), added to it."""
    name, k = item.clip, 1
    while name in seen:
        k += 1
        name = f"{item.clip}~{k}"
    seen.add(name)
    return item if name == item.clip else dataclasses.replace(item, clip=name)
