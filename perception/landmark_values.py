"""The landmarks of one movement as a value: :class:`Landmarks`, with each one's flag.

Measured by :func:`perception.landmarks.movement_landmarks`; kept apart from
the measuring so that the value can be read (reports, tables) without it.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field, fields

__all__ = ["OK", "TOO_FEW", "TRANSPORT_LOST", "Landmarks"]

#: A landmark's flag when nothing casts doubt on it (:meth:`Landmarks.flag`).
OK = "ok"
#: Every landmark's flag where the transport point is never seen long enough for a speed
#: (:attr:`Landmarks.status` ``marker lost``).
TRANSPORT_LOST = "not seen: the transport point is lost throughout"
#: Every landmark's flag where a movement has too few samples for a speed (its number in
#: place of ``{}``; :attr:`Landmarks.status` ``too short``).
TOO_FEW = "not seen: {} samples"
_TOO_FEW = re.compile(re.escape(TOO_FEW).replace(r"\{\}", r"\d+"))
#: Landmarks derived from others: their flag is the first doubtful one of these.
_DERIVED = {"opening": ("mga", "rest_aperture"),
            "peak_speed_seconds": ("peak_speed_time", "movement_time"),
            "mga_seconds": ("mga_time", "movement_time")}


@dataclass(frozen=True)
class Landmarks:
    """The standard landmarks of one reach-to-grasp movement (NaN where not computable).

    Times called shares are fractions of the movement time from its onset
    (0-1); the movement runs from onset to end by :class:`LandmarkParams`.

    Attributes
    ----------
    onset_time, end_time : float
        The movement's onset and end on the recording's clock, s (NaN where
        the recording starts or ends in the movement).
    movement_time : float
        End minus onset, s.
    peak_speed : float
        Peak transport speed, m/s.
    peak_speed_time : float
        When it comes, share.
    deceleration_time : float
        From the peak speed to the end, s.
    mga : float
        Maximum grip aperture, m: the largest tip-to-tip (marker-to-marker)
        distance between onset and end.
    mga_time : float
        When it comes, share.
    contact_aperture : float
        Grip aperture at the movement's end, m.
    aperture_peaks : int or None
        Maxima of the aperture with a prominence of at least
        :attr:`LandmarkParams.peak_prominence` of the opening and
        ``peak_min_prominence`` (see :func:`count_peaks`); None where fewer
        than two are seen and the aperture is missing for long enough to
        hide a second opening (:meth:`LandmarkParams.hides_a_reopening`), or
        where it has fewer than 3 samples.
    rest_aperture : float
        Grip aperture at the movement's onset, m.
    opening_time : float
        When the aperture first exceeds ``rest_aperture`` + ``opening_level``
        of the opening: the grip starts to open, share (NaN where the digits
        were unseen for more than ``max_gap`` then).
    peak_opening_speed : float
        The aperture's fastest widening before the MGA, m/s.
    closing_time : float
        From the MGA to the movement's end, s.
    movements : int or None
        Movements in the recording: 1, plus each stretch outside this one in
        which the transport goes faster than ``second_movement`` of its peak
        (None without a speed).
    flags : mapping of str to str
        Why a landmark is doubtful or missing, by name (one not named is
        ``ok`` where it has a value): ``inside a gap: ...`` (taken where the
        transport point or a digit was lost), ``not seen: ...`` (with why),
        ``bound raised to N % of peak`` (:meth:`flag`).
    """

    movement_time: float = math.nan
    peak_speed: float = math.nan
    peak_speed_time: float = math.nan
    mga: float = math.nan
    mga_time: float = math.nan
    contact_aperture: float = math.nan
    aperture_peaks: int | None = None
    rest_aperture: float = math.nan
    opening_time: float = math.nan
    onset_time: float = math.nan
    end_time: float = math.nan
    deceleration_time: float = math.nan
    peak_opening_speed: float = math.nan
    closing_time: float = math.nan
    movements: int | None = None
    # not compared: two movements with the same numbers are the same landmarks
    flags: Mapping[str, str] = field(default_factory=dict, compare=False)

    def flag(self, name: str) -> str:
        """Whether landmark ``name`` can be trusted: ``ok``, or why not.

        ``inside a gap: ...``, ``not seen: ...`` or ``bound raised to N % of
        peak`` as :func:`movement_landmarks` found it; a derived landmark
        (``opening``, ``peak_speed_seconds``, ``mga_seconds``) takes the
        first doubtful flag of those it comes from; a missing value never
        reads ``ok`` (``not seen`` where nothing said why).

        Parameters
        ----------
        name : str
            A field, or ``opening``, ``peak_speed_seconds``, ``mga_seconds``.
        """
        if name in self.flags:
            return self.flags[name]
        for source in _DERIVED.get(name, ()):
            if (said := self.flag(source)) != OK:
                return said
        value = getattr(self, name)
        if value is None or not math.isfinite(float(value)):
            return "not seen"
        return OK

    @property
    def status(self) -> str:
        """Whether the recording holds the whole movement: ``complete``, ``starts in
        motion``, ``ends in motion`` or ``in motion throughout``; ``marker lost`` where
        the transport point is lost throughout (:data:`TRANSPORT_LOST`) and ``too short``
        where too few samples (:data:`TOO_FEW`) give no speed, so that none tells whether
        the hand moved at all."""
        if math.isnan(self.onset_time) and math.isnan(self.end_time):
            # without a speed the onset and end are unknown, not outside the recording
            why = self.flags.get("onset_time", "")
            if why == TRANSPORT_LOST:
                return "marker lost"
            return "too short" if _TOO_FEW.fullmatch(why) else "in motion throughout"
        if math.isnan(self.onset_time):
            return "starts in motion"
        if math.isnan(self.end_time):
            return "ends in motion"
        return "complete"

    @property
    def opening(self) -> float:
        """How far the hand opened: ``mga - rest_aperture``, m."""
        return self.mga - self.rest_aperture

    @property
    def peak_speed_seconds(self) -> float:
        """When the peak speed comes, s from the onset."""
        return self.peak_speed_time * self.movement_time

    @property
    def mga_seconds(self) -> float:
        """When the MGA comes, s from the onset."""
        return self.mga_time * self.movement_time

    def to_dict(self) -> dict:
        """The landmarks, ``opening``, ``peak_speed_seconds`` and ``mga_seconds`` as JSON
        values (NaN becomes None)."""
        out = {}
        for f in fields(self):
            if f.name == "flags":
                continue
            v = getattr(self, f.name)
            out[f.name] = v if v is None or isinstance(v, int) else _num(v)
        for name in ("opening", "peak_speed_seconds", "mga_seconds"):
            out[name] = _num(getattr(self, name))
        if self.flags:  # only where a landmark is doubtful: older readers see the same keys
            out["flags"] = dict(self.flags)
        return out

    @classmethod
    def from_dict(cls, d: dict | None) -> Landmarks:
        """From :meth:`to_dict`'s output (None and missing keys read as NaN).

        Parameters
        ----------
        d : dict or None
            A ``kinematics`` entry of ``<clip>.recognition.json``.
        """
        d = d or {}
        kw = {"flags": {str(k): str(v) for k, v in (d.get("flags") or {}).items()}}
        for f in fields(cls):
            v = d.get(f.name)
            if f.name == "flags":
                continue
            if f.name in ("aperture_peaks", "movements"):
                kw[f.name] = None if v is None else int(v)
            else:
                kw[f.name] = math.nan if v is None else float(v)
        return cls(**kw)


#: Every landmark's name (the flags' keys).
_NAMES = tuple(f.name for f in fields(Landmarks) if f.name != "flags")


def _num(x) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None
