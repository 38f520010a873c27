"""Tracks -> observations in the model frame.

The model frame (docs/coordinates.md): origin at the object centre, +y from
the demonstrator's start toward the object, metres. Any input comes here as
one :class:`~perception.records.MovementRecord`: metres, x right and
y up, about the object's position in the first frames, at the scale its
object's known diameter (or a given pixel scale) gives; a motion-capture
reach's tracks are metres in its plane already (:attr:`Tracks.units`). The
scene turns the record into the model frame by the direction from the
wrist's rest position to the object: the similarity transform of
:mod:`perception.geometry`, fixed from the first frames.

The movement is scored over its :class:`MovementSpan`: from its onset (the
wrist's displacement from rest, less the model's own latency) to the end of
activity; :func:`movement_span` is its one detector (recognition and
``tracks export --trim``). Marker positions are smoothed by a causal
alpha-beta filter (:mod:`perception.filtering`) before their changes are
compared with predictions: with raw tracks half a pixel of noise randomises
the sign of the small per-frame changes the thesis's confidence rule counts
(docs/recognition.md).
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass, field
from typing import Annotated, NamedTuple

import numpy as np
from pydantic import AfterValidator, Field

from perception.errors import InputError
from perception.filtering import alpha_beta
from perception.geometry import DEFAULT_OBJECT_DIAMETER, SimilarityTransform
from perception.io.pose import is_pose_file
from perception.movement_bounds import end_row, onset_time
from perception.records import MARKERS, MovementRecord, make_record, reading_notes
from perception.resume import Grown, Kept, Ordered, extended, rowwise
from perception.validation import Int, Positive, Tuple, declared

__all__ = [
    "DIGIT_MARKERS",
    "MovementSpan",
    "ObserveParams",
    "Observation",
    "RestScene",
    "check_hand",
    "movement_record",
    "movement_span",
    "observe",
    "rest_scene",
]

log = logging.getLogger(__name__)

#: Markers the recognition needs, in the order of the model's effectors.
DIGIT_MARKERS = ("wrist", "finger", "thumb")
#: Every marker an observation needs: a movement record's.
NEEDED_MARKERS = MARKERS
#: Median absolute deviation -> standard deviation, for normally distributed noise.
MAD_TO_SD = 1.4826


def _range(pair: tuple[float, float]) -> tuple[float, float]:
    if not pair[0] < pair[1]:
        raise ValueError("(low, high) with low < high")
    return pair


def _profile(rows: tuple) -> tuple:
    prof = np.asarray(rows, dtype=float)
    if not (len(prof) >= 2 and np.all(np.diff(prof, axis=0) > 0)):
        raise ValueError("increasing (displacement m, time s) pairs")
    return rows


_Range = Annotated[tuple[Positive, Positive], Tuple, AfterValidator(_range)]
_Frames = Annotated[Int, Field(ge=0)]


@declared
class ObserveParams:
    """How tracks become observations.

    Parameters
    ----------
    object_diameter : float
        Real diameter of the object, m (default: the thesis's 0.10 m ball).
    px_per_m : float, optional
        Image scale; default: the object's apparent diameter in pixels
        (from the tracks) divided by ``object_diameter``.
    mirror : bool
        Mirror the image x axis, for views in which the finger lies on the
        model's -x side (the model puts the finger at +x).
    rest_frames : int
        Frames at the start used to fix the scene (object position, rest posture).
    max_rest_noise : float
        Largest position noise at rest, m, for a clip to be scored: a clip must
        start with the hand still and visible (5 mm: 3 px of DeepLabCut-level
        jitter at 600 px/m still passes).
    max_rest_drift : float
        Largest excursion of a marker from its mean over the rest frames, m
        (or ``rest_noise_factor`` x the noise, if larger).
    rest_noise_factor : float
        Noise SDs a marker may wander at rest before the hand counts as moving.
    max_rest_aperture : float
        Largest distance between the finger and thumb markers at rest, m: the
        digits touch at the start (as in the model).
    hand_size_range : (float, float)
        Plausible distance from the wrist band to the touching digit tips at
        rest, m; outside it the "hand" is not one (a marker on a
        same-coloured object, or a wrong scale).
    frame_period_range : (float, float)
        Plausible median frame period, s (1000 down to 2 frames/s): time
        stamps outside it are not in seconds.
    onset_displacement : float
        Wrist displacement from rest that marks a movement, m (raised to
        ``onset_noise_factor`` x the noise on noisy tracks).
    onset_noise_factor : float
        Noise SDs the onset threshold stays above.
    onset_hold_frames : int
        Frames the wrist must stay beyond the threshold for a movement to count.
    onset_profile : tuple of (float, float)
        ``(displacement m, time s)`` pairs: how long after a movement's
        command onset the wrist has moved that far. Visible motion lags the
        command (the muscle filter), so the onset is the crossing time less
        this latency. The default is the 1 s minimum variance grasp's
        (``tests/test_observe.py`` checks it against the model).
    onset_scale_range : (float, float), optional
        A movement that starts faster or slower than the profile's (a faster
        or nearer reach, a person's quicker rise) is aligned by a time scale:
        the crossing times of the profile's displacements the wrist has
        passed, fitted (least squares) as the profile's latencies times that
        scale plus the onset, the scale kept within this range. The model's
        own 1 s grasps come out near 1 and its 0.6 s ones near 0.75; real
        reaches near 0.6 (1.3-1.8 s, Optotrak) and 0.35 (0.4-0.5 s,
        RTMocap), whose onset the unscaled profile put 40-70 ms early.
        None: the profile as it is (the latency of the first crossing alone).
    end_speed : float
        A hand marker faster than this, m/s (or ``end_noise_factor`` noise SDs
        per frame, if larger), is still moving: the movement ends after the
        last such frame.
    end_noise_factor : float
        Noise SDs per frame a marker must move to count as moving.
    end_speed_window : float
        Time over which those speeds are measured, s (a frame at 30
        frames/s): over one frame of a 120 frames/s clip the noise floor
        would be four times as high.
    end_pad_frames : int
        Frames kept after the last moving frame (the finite difference and
        the filter lag the motion by about that much).
    alpha, beta : float
        Gains of the causal alpha-beta filter applied to every marker.
    min_frames : int
        Fewest frames of movement that can be scored.
    min_movement : float
        Least distance the wrist must get from its rest position during the
        movement, m: less is no reach (a still hand drifting a few mm, a
        tremor), and the clip is refused rather than scored as a movement.
    """

    object_diameter: Positive = DEFAULT_OBJECT_DIAMETER
    px_per_m: Positive | None = None
    mirror: bool = False
    rest_frames: Annotated[_Frames, Field(ge=2)] = 5
    max_rest_noise: Positive = 0.005
    max_rest_drift: Positive = 0.006
    rest_noise_factor: Positive = 6.0
    max_rest_aperture: Positive = 0.04
    hand_size_range: _Range = (0.01, 0.25)
    frame_period_range: _Range = (0.001, 0.5)
    onset_displacement: Positive = 0.002
    onset_noise_factor: Positive = 4.0
    onset_hold_frames: Annotated[_Frames, Field(ge=1)] = 3
    onset_profile: Annotated[tuple[Annotated[tuple[float, float], Tuple], ...], Tuple,
                             AfterValidator(_profile)] = (
        (0.001, 0.091), (0.002, 0.110), (0.003, 0.123), (0.004, 0.133),
        (0.006, 0.151), (0.008, 0.166), (0.012, 0.190))
    onset_scale_range: _Range | None = (0.2, 2.0)
    end_speed: Positive = 0.02
    end_noise_factor: Positive = 6.0
    end_speed_window: Annotated[float, Field(gt=0, le=1)] = 1 / 30
    end_pad_frames: _Frames = 2
    alpha: Annotated[float, Field(gt=0, le=1)] = 0.5
    beta: Annotated[float, Field(ge=0, lt=2)] = 0.15
    min_frames: Annotated[_Frames, Field(ge=3)] = 8
    min_movement: Positive = 0.02

    def onset_latency(self, displacement: float) -> float:
        """Time after the command onset at which the wrist has moved ``displacement`` m.

        Parameters
        ----------
        displacement : float
            Wrist displacement from rest, m.
        """
        d, t = np.asarray(self.onset_profile, dtype=float).T
        return float(np.interp(displacement, d, t))


@dataclass(frozen=True)
class MovementSpan:
    """The part of a clip that is scored: from movement onset to the end of activity.

    Attributes
    ----------
    start, stop : int
        Rows of the tracks, ``[start, stop)``.
    onset_frame, end_frame : int
        Video frames of the first and last scored rows.
    onset_time : float
        Time of the movement's (command) onset on the clip's clock, s; the
        first scored frame is at or just after it.
    """

    start: int
    stop: int
    onset_frame: int
    end_frame: int
    onset_time: float

    @property
    def rows(self) -> slice:
        """``slice(start, stop)`` of the tracks' rows."""
        return slice(self.start, self.stop)

    @property
    def n_frames(self) -> int:
        """Scored frames."""
        return self.stop - self.start


@dataclass(frozen=True, eq=False)
class Observation:
    """A demonstration in the model frame, from movement onset to the end of activity.

    Attributes
    ----------
    clip : str
        Clip name.
    frame : (N,) int array
        Video frame of each sample.
    time : (N,) array
        Time since the movement's onset, s (from the container's time stamps;
        the first sample is at or just after the onset).
    wrist, finger, thumb : (N, 2) arrays
        Causally filtered positions, m; NaN where the marker is lost. The digit
        markers' separation at rest (digits touching) is taken off, so finger
        and thumb are the tips.
    raw : dict of (N, 2) arrays
        Unfiltered positions of the same markers.
    scene : SimilarityTransform
        The pixel-to-model transform.
    dt : float
        Median frame period, s.
    onset_frame, end_frame : int
        Frames where the scored movement starts and ends (inclusive): the
        :class:`MovementSpan` of the tracks.
    start_distance : float
        Distance from the wrist at rest to the object centre, m.
    hand_offset : (2,) array
        Grip midpoint relative to the wrist at rest, m (the hand's size and posture).
    marker_separation : float
        Distance between the digit markers at rest, m (removed from finger and thumb).
    noise : float
        Tracking noise of the positions at rest (robust SD), m.
    object_diameter : float
        Object diameter, m.
    clip_time : (T,) array, optional
        Every sample of the clip, s on the same clock as ``time``.
    clip_raw : (T, 3, 2) array, optional
        Unfiltered wrist, finger and thumb positions over the whole clip, m
        (the landmarks' movement may end after the scored span).
    clip_wrist : (T, 2) array, optional
        The causally filtered wrist over the whole clip, m (as ``wrist``):
        the hand may come to rest after the scored span ends, which the end
        rule closes early when the tracking is noisy.
    notes : tuple of str
        What was done to the tracks before they were observed: the cleaning's
        repairs per marker (:func:`perception.track_cleaning.cleaning_notes`).
    """

    clip: str
    frame: np.ndarray
    time: np.ndarray
    wrist: np.ndarray = field(repr=False)
    finger: np.ndarray = field(repr=False)
    thumb: np.ndarray = field(repr=False)
    raw: dict = field(repr=False)
    scene: SimilarityTransform = field(repr=False)
    dt: float = 1 / 30
    onset_frame: int = 0
    end_frame: int = 0
    start_distance: float = 0.0
    hand_offset: np.ndarray = field(default_factory=lambda: np.zeros(2), repr=False)
    object_diameter: float = DEFAULT_OBJECT_DIAMETER
    marker_separation: float = 0.0
    noise: float = 0.0
    clip_time: np.ndarray | None = field(default=None, repr=False)
    clip_raw: np.ndarray | None = field(default=None, repr=False)
    clip_wrist: np.ndarray | None = field(default=None, repr=False)
    notes: tuple[str, ...] = ()

    @property
    def n_frames(self) -> int:
        """Number of scored samples N."""
        return len(self.time)

    @property
    def midpoint(self) -> np.ndarray:
        """(N, 2) grip midpoint (finger + thumb) / 2, m (thesis eq. 5.3)."""
        return 0.5 * (self.finger + self.thumb)

    @property
    def r(self) -> np.ndarray:
        """(N,) distance from grip midpoint to object centre, m (thesis eq. 5.4)."""
        return np.linalg.norm(self.midpoint, axis=-1)

    @property
    def g(self) -> np.ndarray:
        """(N,) grip aperture |finger - thumb|, m (thesis eq. 5.5)."""
        return np.linalg.norm(self.finger - self.thumb, axis=-1)


class RestScene(NamedTuple):
    """What the first frames of a clip fix (:func:`rest_scene`).

    The offline observation and the online recogniser
    (:class:`perception.online.OnlineRecognizer`) both start from it.

    Attributes
    ----------
    source : str
        What errors name: the tracks file, else the clip.
    time : (T,) float
        Time stamps, s (finite, increasing).
    dts : (T-1,) float
        Frame periods, s.
    dt : float
        The median frame period, s.
    transform : SimilarityTransform
        Pixels (or a reach's metres in its plane) -> model frame: the object
        at the origin, the wrist's rest position on the -y axis, metres.
    raw : (T, 3, 2) float
        Wrist, finger and thumb markers in the model frame, m, unfiltered.
    rest : (3, 2) float
        The mean rest posture, m, in that order.
    noise : float
        Tracking noise at rest (robust SD), m.
    """

    source: str
    time: np.ndarray
    dts: np.ndarray
    dt: float
    transform: SimilarityTransform
    raw: np.ndarray
    rest: np.ndarray
    noise: float


class _Prepared(NamedTuple):
    """A clip's scene, its smoothed positions (T, 3, 2) m and its movement."""

    name: str
    frames: np.ndarray
    scene: RestScene
    filtered: np.ndarray
    span: MovementSpan


def _clip_name(tracks, clip: str | None) -> str:
    return clip or getattr(tracks, "name", None) or "clip"


def _source(tracks, name: str) -> str:
    """What an error names: the tracks file the clip was loaded from, else the clip."""
    path = getattr(tracks, "path", None)
    return str(path) if path is not None else name


def movement_record(tracks, params: ObserveParams | None = None, *,
                    clip: str | None = None) -> MovementRecord:
    """The movement of some tracks in metres, x right and y up, about the object at rest:
    the record :func:`observe` turns into the model frame (docs/coordinates.md).

    Parameters
    ----------
    tracks : Tracks
        A video's or pose file's (pixels, y down; the scale from ``params.px_per_m``
        or the object's apparent size over ``params.object_diameter``), or a
        motion-capture reach's in its plane (:attr:`~perception.io.tracks.Tracks.units`
        ``"m"``). The markers ``wrist``, ``finger``, ``thumb`` and ``object`` are needed.
    params : ObserveParams, optional
        The scale, the object's size, the rest frames and the clock's checks.
    clip : str, optional
        Clip name for messages and the record (default: the tracks').

    Raises
    ------
    InputError
        Naming the tracks file (else the clip): a needed marker is missing or
        never seen, the time stamps are not increasing finite seconds, the clip
        does not start with every marker seen, or the scale is unknown.
    """
    from perception.boundary import expect
    from perception.io.tracks import Tracks

    expect(tracks, Tracks, "movement_record(tracks=)", hint="Tracks.load or track_video")
    expect(params, ObserveParams, "movement_record(params=)", optional=True)
    return make_record(tracks, ObserveParams() if params is None else params, clip)


def _scene_transform(record: MovementRecord, tracks, params: ObserveParams
                     ) -> SimilarityTransform:
    """The tracks -> model transform: the record's turned by the approach, the
    direction from the wrist at rest toward the object (taken in the input's units: the
    same angle as in the record's metres, and the bits it had before the record)."""
    d = (np.median(np.asarray(tracks.marker("wrist"), dtype=float)[: params.rest_frames],
                   axis=0) - record.input_transform.origin_px)
    # from the wrist toward the object, y up
    approach = np.array([-d[0], d[1]]) if record.input_transform.y_down else -d
    if np.linalg.norm(approach) < 1e-6:
        raise InputError("impossible geometry: the wrist starts on the object", record.source)
    return dataclasses.replace(record.input_transform, mirror=params.mirror,
                               rotation=float(np.arctan2(approach[1], approach[0])))


def _rest_noise(raw: np.ndarray, params: ObserveParams, name: str) -> tuple[float, np.ndarray]:
    """Tracking noise at rest (robust SD, m) and the mean rest posture (3, 2) m.

    Refuses a clip whose hand is not still over the rest frames.
    """
    rest = raw[: params.rest_frames]
    steps = np.diff(rest, axis=0).reshape(-1, 2)
    # A frame-to-frame change carries the noise of two frames: divide by sqrt 2. Each axis
    # about its own median: the estimate must not change with the x axis's sign (mirrored)
    noise = MAD_TO_SD * np.median(np.abs(steps - np.median(steps, axis=0))) / np.sqrt(2)
    mean = rest.mean(axis=0)
    drift = np.linalg.norm(rest - mean, axis=-1).max()
    if noise > params.max_rest_noise or drift > max(params.max_rest_drift,
                                                    params.rest_noise_factor * noise):
        raise InputError(f"the clip must start with the hand at rest: its markers move "
                         f"{drift * 1000:.1f} mm (noise {noise * 1000:.1f} mm) over the first "
                         f"{params.rest_frames} frames", name)
    return float(noise), mean


def rest_scene(tracks, params: ObserveParams | None = None, *,
               clip: str | None = None) -> RestScene:
    """The scene a clip's first frames fix: transform, rest posture and noise.

    Parameters
    ----------
    tracks : Tracks
        See :func:`observe`.
    params : ObserveParams, optional
        Scale and rest settings.
    clip : str, optional
        Clip name for messages.

    Raises
    ------
    InputError
        A needed marker is missing or never seen, the time stamps are not
        finite, increasing seconds, the scale is unknown, or the clip does
        not start with the hand still and visible.
    """
    params = ObserveParams() if params is None else params
    where = _source(tracks, _clip_name(tracks, clip))  # the tracks file where there is one
    # the pipeline settles a clip's start, then observes it: one scene for both
    key = (where, params, tuple(tracks.markers), tracks.units,
           tracks.object_diameter_px() if params.px_per_m is None else None)
    kept = _SCENES.longest(key, (tracks.time, tracks.position))
    longer = None
    if kept is not None:
        if len(kept[0][0]) == len(tracks.time):
            return kept[1][0]
        longer = _extended(*kept[1], len(kept[0][0]), tracks, params)
    if longer is not None:
        scene, order = longer
    else:
        record = make_record(tracks, params, clip, notes=False)  # observe gives them
        time, dts = record.time, np.diff(record.time)
        transform = _scene_transform(record, tracks, params)
        raw = np.stack([transform.rotated(getattr(record, m)) for m in DIGIT_MARKERS], axis=1)
        noise, rest = _rest_noise(raw, params, where)
        # rows a longer prefix appends to (resume.Grown); the periods' median kept in order
        order = Ordered(dts)  # finite: the record checked them
        scene = RestScene(where, time, Grown(dts).rows(), order.median(), transform,
                          Grown(raw).rows(), rest, noise)
    scene.rest.flags.writeable = False  # shared by the observations made from the same rows
    _SCENES.keep(key, (tracks.time, tracks.position), (scene, order))
    return scene


#: The last scene fixed in this thread, and the rows it was fixed from (:func:`rest_scene`);
_SCENES, _CLOCKS = Kept(1), Kept(4)  # rows on an observation's clock, digits (observe)


def _extended(scene: RestScene, order: Ordered, n: int, tracks, params: ObserveParams):
    """The scene fixed from the first ``n`` rows of ``tracks`` (its frame periods in
    ``order``) with the rows after them, and their periods in order; or None.

    What the first rows fix (the transform, the rest posture and its noise, the
    checks on them) stands; the new rows are checked, mapped to the model frame (a
    row maps alike in any array: :meth:`SimilarityTransform.to_model`) and appended
    (:func:`~perception.resume.extended`), their periods put in ``order``. None where
    a new row would be refused (:func:`rest_scene` then refuses them as afresh).
    """
    pos = np.asarray(tracks.position, dtype=float)
    time = np.asarray(tracks.time, dtype=float)
    markers = list(tracks.markers)
    if not np.isfinite(time[n:]).all() or np.isinf(
            pos[n:, [markers.index(m) for m in NEEDED_MARKERS]]).any():
        return None
    if np.any((periods := np.diff(time[n - 1:])) <= 0):
        return None
    dts = extended(scene.dts, periods)
    dt = (order := order.extended(periods, lambda: dts)).median()
    lo, hi = params.frame_period_range
    if not lo * (1 - 1e-6) <= dt <= hi * (1 + 1e-6):
        return None
    # the three markers' new rows mapped in one call (a row maps alike in any array)
    new = scene.transform.to_model(pos[n:, [markers.index(m) for m in DIGIT_MARKERS]])
    return scene._replace(time=time, dts=dts, dt=dt, raw=extended(scene.raw, new)), order


def _prepare(tracks, params: ObserveParams, name: str) -> _Prepared:
    """Scene, smoothed model-frame positions and the movement span of some tracks."""
    sc = rest_scene(tracks, params, clip=name)
    filtered = alpha_beta(sc.raw, np.concatenate([[sc.dt], sc.dts]), params.alpha, params.beta)
    onset = onset_time(filtered, sc.time, sc.noise, params, sc.source)
    start = int(np.searchsorted(sc.time, onset))
    end = end_row(filtered, sc.time, sc.noise, sc.dt, params)
    if end - start + 1 < params.min_frames:
        raise InputError(f"movement too short to score: {end - start + 1} frames "
                         f"(need at least {params.min_frames})", sc.source)
    frames = np.asarray(getattr(tracks, "frame", np.arange(len(sc.time))))
    span = MovementSpan(start, end + 1, int(frames[start]), int(frames[end]), onset)
    return _Prepared(name, frames, sc, filtered, span)


def movement_span(tracks, params: ObserveParams | None = None, *,
                  clip: str | None = None) -> MovementSpan:
    """The movement :func:`observe` scores: onset to end of activity.

    Parameters
    ----------
    tracks : Tracks
        See :func:`observe`.
    params : ObserveParams, optional
        Scale, filter and onset settings.
    clip : str, optional
        Clip name for messages.

    Raises
    ------
    InputError
        As :func:`observe`, for everything up to finding the movement.
    """
    from perception.boundary import expect
    from perception.io.tracks import Tracks

    expect(tracks, Tracks, "movement_span(tracks=)", hint="Tracks.load or track_video")
    expect(params, ObserveParams, "movement_span(params=)", optional=True)
    params = ObserveParams() if params is None else params
    return _prepare(tracks, params, _clip_name(tracks, clip)).span


def check_hand(scene: RestScene, params: ObserveParams | None = None) -> None:
    """Refuse a rest posture that does not look like a hand.

    The digits must touch, and sit in front of the wrist at a hand's
    distance (``params.max_rest_aperture``, ``params.hand_size_range``).

    Raises
    ------
    InputError
        Naming ``scene.source``.
    """
    params = ObserveParams() if params is None else params
    wrist, finger, thumb = scene.rest
    apart = float(np.linalg.norm(finger - thumb))
    size = float(np.linalg.norm(0.5 * (finger + thumb) - wrist))
    lo, hi = params.hand_size_range
    if apart > params.max_rest_aperture or not lo <= size <= hi:
        raise InputError(f"the hand at rest does not look like a hand: finger and thumb "
                         f"markers {apart * 100:.1f} cm apart, {size * 100:.1f} cm from the "
                         + ("wrist (keypoints on the wrong markers? check `keypoints`, and "
                            "`object_diameter_px` or `px_per_m`)" if is_pose_file(scene.source)
                            else "wrist (a same-coloured object taken for a marker? give `rois` "
                            "when tracking; or a wrong scale: check `object_diameter`, the "
                            "object's real size, or `px_per_m`)"), scene.source)


def observe(tracks, params: ObserveParams | None = None, *, clip: str | None = None) -> Observation:
    """Turn marker tracks into an :class:`Observation` in the model frame.

    Parameters
    ----------
    tracks : Tracks
        Tracks with ``time`` (T,) s, ``frame`` (T,), ``markers`` (names),
        ``position`` (T, M, 2) px with NaN where lost, and the object's apparent
        size (``object_diameter_px()``); the markers ``wrist``, ``finger``,
        ``thumb`` and ``object`` are needed.
    params : ObserveParams, optional
        Scale, filter and onset settings.
    clip : str, optional
        Clip name for messages and results (default: from the tracks).

    Returns
    -------
    Observation

    Raises
    ------
    InputError
        If a needed marker is missing or never seen, the object is never seen,
        the scale is unknown, the time stamps are not finite seconds, the clip
        does not start with a still, visible hand that looks like a hand, no
        movement is found, or the movement is too short to score.
    """
    from perception.boundary import expect
    from perception.io.tracks import Tracks

    expect(tracks, Tracks, "observe(tracks=)", hint="Tracks.load or track_video")
    expect(params, ObserveParams, "observe(params=)", optional=True)
    params = ObserveParams() if params is None else params
    p = _prepare(tracks, params, _clip_name(tracks, clip))
    sc = p.scene
    check_hand(sc, params)
    start, finger0, thumb0 = sc.rest
    # The digits touch at rest (as in the model), so the markers' separation
    # then is where they sit on the digits, outside the tips: take it off.
    half = 0.5 * (finger0 - thumb0)
    filt = rowwise(_CLOCKS, half.tobytes(), p.filtered, lambda f: np.stack(  # resumed
        [f[:, 0], f[:, 1] - half, f[:, 2] + half], axis=1))  # a stream's: a row more
    sl = p.span.rows
    moved = float(np.nanmax(np.linalg.norm(filt[sl, 0] - start, axis=-1), initial=0.0))
    if moved < params.min_movement:
        raise InputError(f"no movement: the wrist moves {moved * 1000:.0f} mm (a reach moves at "
                         f"least {params.min_movement * 1000:.0f} mm)", sc.source,
                         field="wrist")
    log.info("%s: onset at frame %d, %d frames scored, start distance %.3f m",
             p.name, p.span.onset_frame, p.span.n_frames, np.linalg.norm(start))
    return Observation(
        clip=p.name,
        frame=p.frames[sl],
        time=sc.time[sl] - p.span.onset_time,
        wrist=filt[sl, 0],
        finger=filt[sl, 1],
        thumb=filt[sl, 2],
        raw={m: sc.raw[sl, i] for i, m in enumerate(DIGIT_MARKERS)},
        noise=sc.noise,
        scene=sc.transform,
        dt=sc.dt,
        onset_frame=p.span.onset_frame,
        end_frame=p.span.end_frame,
        start_distance=float(np.linalg.norm(start)),
        hand_offset=0.5 * (finger0 + thumb0) - start,
        object_diameter=params.object_diameter,
        marker_separation=float(np.linalg.norm(2 * half)),
        clip_time=rowwise(_CLOCKS, p.span.onset_time, sc.time, lambda t: t - p.span.onset_time),
        clip_raw=sc.raw,
        clip_wrist=filt[:, 0],
        notes=reading_notes(tracks),
    )
