"""What a reach is, and the settings that find it: the data :mod:`perception.reaches` works on.

:class:`MarkerMap` (which markers are the thumb, finger, wrist and object),
:class:`ReachParams` (how reaches are found and brought into their plane),
:class:`Movement` (one movement of the transport point and the rules that
bounded it), :class:`Reach` (a reach to grasp, in the recording's frame) and
:class:`Unscored` (a trial or movement that gives no reach, and why), with
the constants the finder and the tracks share. docs/reaches.md describes
the rules.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Annotated

import numpy as np
from pydantic import AfterValidator, BeforeValidator, Field

from perception.cleaning import CleaningParams
from perception.errors import InputError
from perception.landmarks import LandmarkParams
from perception.validation import NonNegative, Positive, Tuple, declared

__all__ = ["MIN_SAMPLES", "OBJECT_WORDS",
           "MarkerMap", "Movement", "Reach", "ReachParams", "Unscored", "digit_number",
           "ever_seen"]

#: Fewest samples a trial needs to be searched for reaches (the low-pass filter's own
#: need is 3 x its order + 1 per seen stretch), and a reach to be scored.
MIN_SAMPLES = 10
#: A hand is still while its low-passed position stays within this, m, over
#: :data:`_STILL_WINDOW`: its speed then is the recording's noise floor.
_STILL_RANGE = 0.002
_STILL_WINDOW = 0.2


#: Words in a marker's (or keypoint's) name that make it the object (:meth:`MarkerMap.guess`).
OBJECT_WORDS = ("object", "pillow", "target", "cube", "block", "cup", "mug", "ball", "bottle",
                "cylinder", "sphere", "dowel")


def ever_seen(path) -> bool:
    """Whether a marker's (N, 3) path has one sample seen (all three coordinates finite).

    The readers turn a C3D sample's negative residual and a table's all-zero
    sample into NaN, so a marker lost throughout is all NaN here.
    """
    return bool(np.isfinite(np.asarray(path, dtype=float)).all(axis=1).any())




#: A side of the body in a marker's name: ``L_``, ``Left.``, ``_R``, or a bare ``L``/``R``
#: before a hand word (``LTHUMB``, ``RWRIST``, ``RINDEX``).
_SIDE = re.compile(r"^(left|right|l|r)[\s_.:-]|[\s_.:-](left|right|l|r)$|"
                   r"^(l|r)(?=thumb|index|finger|wrist|wr[ab]|hand)", re.IGNORECASE)
#: Words of the digits a hand is told by.
_DIGITS = ("thumb", "index", "finger")
#: A digit by its anatomical number, a word of the name: ``right_d1_tip``, ``L.D2``,
#: ``digit1`` (digit 1 the thumb, digit 2 the index, as hand labs number them).
_NUMBERED = re.compile(r"(?:^|[\s_.:-])(?:d|digit)([12])(?=$|[\s_.:-])", re.IGNORECASE)


def digit_number(name: str) -> int | None:
    """The digit a marker's name numbers (``right_d1_tip``: 1, the thumb), where it names
    no digit in words; else None.

    Parameters
    ----------
    name : str
        A marker's name.
    """
    numbered = _NUMBERED.search(name)
    if numbered is None or any(w in name.lower() for w in _DIGITS):
        return None
    return int(numbered.group(1))


def _says(name: str, *words: str) -> bool:
    """Whether a marker's name says one of the digit ``words`` (``thumb``, ``index``,
    ``finger``), in words or by the digit's number (``d1`` the thumb, ``d2`` the index)."""
    low = name.lower()
    numbered = _NUMBERED.search(name)
    number = {"1": ("thumb",), "2": ("index", "finger")}[numbered.group(1)] if numbered else ()
    return any(w in low or w in number for w in words)


def _joint(name: str) -> int:
    """A point's number along its digit (``thumb_4`` 4, ``index3`` 3); 0 without one."""
    match = re.search(r"(\d+)$", name)
    return int(match.group(1)) if match else 0


def _side(name: str) -> str | None:
    """``"l"`` or ``"r"`` where a marker's name says a side, else None."""
    match = _SIDE.search(name)
    return None if match is None else next(g for g in match.groups() if g)[0].lower()


def _one_hand(names: list[str], paths) -> str | None:
    """The side whose hand the digits are taken from where the names say two (None if
    they do not): the one whose thumb and finger markers move farthest, else the right."""
    sides = {_side(n) for n in names if _says(n, *_DIGITS)} - {None}
    if len(sides) < 2:
        return None
    if paths is None:
        return "r"

    def travel(side):  # the largest range of a seen digit marker's coordinates (NaN: lost)
        ranges = [float(np.max(np.nanmax(p, axis=0) - np.nanmin(p, axis=0)))
                  for n in names if _side(n) == side and _says(n, *_DIGITS)
                  and ever_seen(p := np.asarray(paths[n], dtype=float))]
        return max(ranges, default=0.0)

    return max(("r", "l"), key=travel)


def _marker_name(name: str) -> str:
    if not name.strip():
        raise ValueError("a marker's name, not an empty one")
    return name


def _names(value):
    # one name is a tuple of one, not of its letters ("eyeL" -> ("eyeL",))
    return (value,) if isinstance(value, str) else value


#: A marker's name (not empty).
MarkerName = Annotated[str, AfterValidator(_marker_name)]
#: Markers whose mean is taken: a tuple of names (a list, or one name, is taken as one).
MarkerNames = Annotated[tuple[MarkerName, ...], BeforeValidator(_names), Tuple]


@declared
class MarkerMap:
    """Which markers of a recording are the thumb, the finger, the wrist and the object.

    Parameters
    ----------
    thumb, finger : str
        The thumb and index tips' markers.
    wrist : tuple of str
        Markers whose mean is the wrist (none: the grip midpoint carries the
        transport). One name is taken as a tuple of one.
    object : tuple of str
        Markers whose mean is the object's centre (none: where the grip closes).
    """

    thumb: MarkerName = "thumb"
    finger: MarkerName = "index"
    wrist: MarkerNames = ()
    object: MarkerNames = ()

    def __post_init__(self) -> None:
        # one marker in two roles measures nothing: a grip of a marker and itself never
        # opens, a wrist or object that is a digit moves with the grip
        if self.thumb == self.finger:
            raise InputError(f"the thumb and the finger are the same marker {self.thumb!r}: "
                             "each digit needs a marker of its own", None, field="finger")
        digits = {self.thumb: "thumb", self.finger: "finger"}
        for role, names in (("wrist", self.wrist), ("object", self.object)):
            for m in names:
                if m in digits:
                    raise InputError(f"the {role} marker {m!r} is also the {digits[m]}: name "
                                     f"another marker for the {role}", None, field=role)
        both = set(self.wrist) & set(self.object)
        if both:
            raise InputError(f"marker{'s' if len(both) > 1 else ''} "
                             f"{', '.join(map(repr, sorted(both)))} both wrist and object",
                             None, field="object")

    @classmethod
    def guess(cls, names) -> MarkerMap:
        """The mapping a recording's marker names suggest (``thumb*``, ``index*``, ...).

        Tips are preferred (``thumb_tip`` over ``thumb_middle``), then a
        point not numbered, then the highest-numbered (``thumb_4`` as OpenPose
        numbers them); markers
        whose name says hand or wrist are the wrist; a name with one of
        :data:`OBJECT_WORDS` (``object``, ``target``, ``cube``, ``cup``, ...) the
        object. Given the markers' paths, a marker never seen (every sample
        missing) is no wrist or object, and a digit only where no other marker's
        name says that digit. Where the names say two hands (``L_THUMB`` and
        ``R_THUMB``, ``Left_index``, ``RWRIST``), the thumb, finger and wrist
        are one hand's: the one whose digits move farthest, given the paths,
        else the right.

        Parameters
        ----------
        names : sequence of str, or mapping of str to (N, 3) arrays
            The recording's marker names, or its markers by name.
        """
        paths = names if isinstance(names, Mapping) else None
        names = list(names)
        low = {n: n.lower() for n in names}
        seen = {n: paths is None or ever_seen(paths[n]) for n in names}
        hand = _one_hand(names, paths)
        if hand is not None:  # the other hand's markers are no part of the grasp
            names = [n for n in names if _side(n) in (None, hand)]

        def pick(*words):
            hits = [n for n in names if _says(n, *words)]
            # a marker seen before one never seen, then a tip before another point, then
            # one not numbered (index beside index2), then the most distal of numbered
            # points (OpenPose's thumb_1 ... thumb_4: 4 the tip)
            hits.sort(key=lambda n: (not seen[n], "tip" not in low[n], _joint(low[n]) > 0,
                                     -_joint(low[n])))
            return (hits or [None])[0]

        thumb = pick("thumb")
        finger = pick("index", "finger")
        wrist = tuple(n for n in names if "wrist" in low[n] and seen[n]) or tuple(
            n for n in names if low[n].startswith("hand") and seen[n])
        obj = tuple(n for n in names if seen[n] and any(w in low[n] for w in OBJECT_WORDS))
        return cls(thumb or "thumb", finger or "index", wrist, obj)

    def roles(self) -> list[tuple[str, str]]:
        """Each mapped marker with its role: ``[("thumb", "thumb"), ("index", "finger"), ...]``."""
        return [(self.thumb, "thumb"), (self.finger, "finger"),
                *((m, "wrist") for m in self.wrist), *((m, "object") for m in self.object)]

    def matched(self, names) -> MarkerMap:
        """This mapping with each ``Subject:Marker`` name the recording holds without its
        subject (the readers read Vicon's labels so) given as the recording's own.

        Parameters
        ----------
        names : collection of str
            The recording's marker names.
        """
        names = set(names)

        def own(name: str) -> str:
            short = name.rpartition(":")[2]
            return short if name not in names and short in names else name

        return MarkerMap(own(self.thumb), own(self.finger), tuple(map(own, self.wrist)),
                         tuple(map(own, self.object)))

    def check(self, names, source) -> None:
        """Refuse a mapping that names a marker the recording lacks."""
        names = set(names)
        for role, wanted in (("thumb", (self.thumb,)), ("finger", (self.finger,)),
                             ("wrist", self.wrist), ("object", self.object)):
            for m in wanted:
                alike = sorted(n for n in names if n.casefold() == m.casefold())
                if m not in names and len(alike) > 1:
                    # which of them was meant is not ours to choose
                    raise InputError(f"{m!r} for the {role} matches {len(alike)} markers but "
                                     f"for case ({', '.join(map(repr, alike))}): name one "
                                     "exactly", source, field="markers")
                if m not in names:
                    raise InputError(f"no marker {m!r} for the {role} (the recording has "
                                     f"{', '.join(sorted(names))}): say which is which with "
                                     f"`markers` ({role}=NAME)", source, field="markers")


@declared
class ReachParams:
    """How reaches are found and brought into their plane.

    Parameters
    ----------
    landmarks : LandmarkParams
        The onset and end rule (and the low-pass filter) that bound a movement.
    cleaning : CleaningParams
        How spikes, held and missing samples are found and which gaps are bridged.
    min_travel : float
        Least distance the transport point goes from a movement's onset to its
        end, m (less is an adjustment, not a movement); also the least on
        each side of a turn that parts two movements.
    min_opening : float
        A grip that opens less than this above its aperture at a movement's
        onset, m, says nothing of a grasp (a whole-hand grasp from a flat
        hand); one that opens more tells a reach from a transport or a lift
        where the transport alone cannot (docs/reaches.md).
    min_speed : float
        Least peak speed of a movement, m/s (a drift of the resting hand is none).
    turn : float
        A movement whose path turns by this much or more, degrees, at a
        minimum of its speed where the grip is closing from its widest (or it
        barely changes) is two movements: a reach and the object's transport
        or a lift. A turn of 135 degrees or more (a withdrawal
        and the next reach) parts them whatever the grip.
    object_moved : float
        The object has moved when its markers' mean is this far from where it
        was at the reach's onset, m (the reach ends where that motion began).
    object_position : (3,) tuple, optional
        The object's centre in the recording's frame, m (instead of markers
        or where the grip closes).
    object_size : float, optional
        The object's size across the grip, m.
    approach : float
        With object markers, a movement is a reach when the hand ends at
        least this share of its starting distance nearer the object (a marker
        set on the back of the hand stops well short of the object's centre).
    returned : float
        Without object markers, the hand is back from a reach (the next
        outward movement may be a reach again) when a movement ends within
        this share of the reach's length of where the reach began.
    min_rest : float
        Least stillness before a reach's onset the recognition needs, s: a
        reach with less is given that much, held at its first position.
    wrist_behind : float
        Where a reach without a wrist marker gets one: this far behind the
        grip midpoint, m (``wrist_synthesised``).
    tail : float
        Time kept after a reach's end (up to the next movement's onset), s:
        the still hand the recognition's end rule reads.
    """

    landmarks: LandmarkParams = field(default_factory=LandmarkParams)
    cleaning: CleaningParams = field(default_factory=CleaningParams)
    min_travel: Positive = 0.05
    min_opening: NonNegative = 0.015
    min_speed: Positive = 0.05
    turn: Annotated[float, Field(gt=0, lt=180)] = 45.0
    object_moved: Positive = 0.01
    object_position: Annotated[tuple[float, float, float], Tuple] | None = None
    object_size: Annotated[float, Field(gt=0, lt=1)] | None = None
    approach: Annotated[float, Field(gt=0, le=1)] = 0.4
    returned: Annotated[float, Field(gt=0, le=1)] = 0.5
    min_rest: Positive = 0.3
    wrist_behind: Annotated[float, Field(ge=0, le=0.3)] = 0.06
    tail: Positive = 0.5


@dataclass(frozen=True, eq=False)
class Reach:
    """One reach of a recording, in the recording's frame.

    Attributes
    ----------
    name : str
        ``<trial>`` or ``<trial>-reach<k>`` when a trial holds several.
    source : str
        The file.
    time : (N,) array
        Sample times, s, from the sample before the reach's rest to its end's
        padding; never earlier than the end of the movement before it.
    transport : (N, 3) array
        The transport point (grip midpoint, or wrist), m, NaN where lost.
    finger, thumb : (N, 3) arrays
        The digit tips, m.
    wrist : (N, 3) array or None
        The mapped wrist, m.
    object : (3,) array or None
        The object's centre from markers (where it stands before the hand
        moves it) or as given, m.
    onset, end : int
        Rows of the movement's onset and end.
    notes : tuple of str
        What was repaired or inferred.
    onset_bound, end_bound : str
        The rule that placed the onset and the end: the field's (``"5 % of
        peak speed"``), ``"the speed minimum between two movements (N % of
        peak)"`` or ``"the object's first motion"``.
    factors : mapping of str to str
        Its trial's design factors (participant, condition, ...: the trial's
        columns and the file's name, :mod:`perception.factors`), as written.
    trial_number : str
        Its trial's id as the trial column writes it (``"38"``), or the
        trial's 1-based index in a file without one.
    reach_number : int or None
        Which reach of its trial, from 1 (the ``-reach<k>`` of its name).
    """

    name: str
    source: str
    time: np.ndarray
    transport: np.ndarray
    finger: np.ndarray
    thumb: np.ndarray
    wrist: np.ndarray | None
    object: np.ndarray | None
    onset: int
    end: int
    notes: tuple[str, ...] = ()
    onset_bound: str = "5 % of peak speed"
    end_bound: str = "5 % of peak speed"
    factors: Mapping[str, str] = field(default_factory=dict)
    trial_number: str = ""
    reach_number: int | None = None

    @property
    def aperture(self) -> np.ndarray:
        """(N,) 3D thumb-index distance, m."""
        return np.linalg.norm(self.finger - self.thumb, axis=1)

    @property
    def bound(self) -> str:
        """Which rules bound the reach, in words (``"5 % of peak speed"``, or onset and end
        apart when they differ)."""
        if self.onset_bound == self.end_bound:
            return self.onset_bound
        return f"onset: {self.onset_bound}; end: {self.end_bound}"


@dataclass(frozen=True)
class Unscored:
    """A trial, or a movement in it, that gives no scored reach, and why.

    Every trial of a recording leaves either reaches or at least one of
    these, so that nothing is dropped without a word.

    Attributes
    ----------
    name : str
        The trial's name, or ``<trial>-reach<k>`` for one movement of it.
    source : str
        The file.
    status : str
        A short word for what happened, the outputs' ``status`` column:
        ``no reach``, ``starts in motion``, ``ends in motion``, ``too short``,
        ``marker lost`` (docs/reaches.md).
    reason : str
        The same in a sentence ("no reach: the hand never moved",
        "too short: 3 samples", "marker lost throughout: index").
    onset_time, end_time : float
        Where the movement starts and ends, s, on the trial's clock (NaN if unknown).
    factors : mapping of str to str
        Its trial's design factors, as :attr:`Reach.factors`.
    trial_number : str
        Its trial's id, as :attr:`Reach.trial_number`.
    reach_number : int or None
        Which reach candidate of its trial it is, from 1, for a movement
        (``-reach<k>``); None for a whole trial that gives none.
    """

    name: str
    source: str
    status: str
    reason: str
    onset_time: float = math.nan
    end_time: float = math.nan
    factors: Mapping[str, str] = field(default_factory=dict, hash=False)
    trial_number: str = ""
    reach_number: int | None = None


@dataclass(frozen=True)
class Movement:
    """One movement of the transport point (:func:`find_movements`).

    Attributes
    ----------
    onset, end : int or None
        Rows of its onset and end; None where the recording starts or ends in it.
    peak : int
        Row of its peak speed.
    onset_bound, end_bound : str
        The rule that placed each (see :attr:`Reach.onset_bound`).
    kind : str
        ``"reach"``, ``"after"`` (what follows a reach: transport, lift,
        release, return) or ``"other"``, once classified
        (:func:`classify_movements`); ``""`` before.
    reason : str
        Why a movement is not a reach, in words.
    """

    onset: int | None
    peak: int
    end: int | None
    onset_bound: str
    end_bound: str
    kind: str = ""
    reason: str = ""


