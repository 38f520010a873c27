"""One trial's kinematics at a glance: transport speed and grip aperture with their landmarks.

:func:`kinematics_figure` draws, over the whole clip, the transport's speed
(mm/s: the wrist's, or the grip midpoint's where no wrist was recorded)
above the grip aperture (mm), sharing the time axis (the recording's clock
where it is known), with the
landmarks of :func:`perception.landmarks.observed_landmarks` marked on them:
the movement's onset and end (lines across both panels, the movement
shaded between them), the peak speed, the maximum grip aperture (MGA, with
its value) and where the grip starts to open. The curves are the ones the
landmarks are measured on (:class:`~perception.landmarks.LandmarkParams`'s
low-pass filter of the clip's unfiltered markers), so every mark sits on
its curve. It is the lab's per-trial figure, in mm and mm/s, each landmark
labelled with its value; the report writes it as ``<clip>.kinematics.png``
(or ``.svg``, ``.pdf``: :func:`~perception.report.figures.write_figure`).

Drawn as :mod:`perception.report.figures` draws: a matplotlib ``Figure`` on
an Agg canvas, never through pyplot, matplotlib imported with the first figure.
"""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING

import numpy as np

from perception.io.names import printable
from perception.landmarks import LandmarkParams, Landmarks
from perception.report.canvas import kept_figure, new_canvas, quicker_legend
from perception.report.figures import LEGEND_PT, _legend, _title

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from perception.observation import Observation
    from perception.recognition.result import Recognition

__all__ = ["kinematic_traces", "kinematics_figure", "kinematics_title", "time_axis",
           "transport_label"]

MM = 1000.0
#: The figure's size, inches; margins around the two panels (left, right, the
#: gap between them, below for the time axis and the legend, above for the
#: title), inches.
SIZE = (8.0, 6.6)
LEFT, RIGHT, GAP, BOTTOM, TOP = 0.9, 0.25, 0.2, 1.1, 0.6
#: The panels' y axes reach at least this high, mm/s and mm: tracking noise on a
#: hand that stays still or closed is not blown up to fill its panel.
MIN_TOP = (100.0, 40.0)
#: Colours: transport, grip, the movement's bounds and its shading.
SPEED_COLOUR, GRIP_COLOUR, BOUND_COLOUR, SHADE_COLOUR = "C0", "C3", "0.25", "0.55"


def kinematic_traces(obs: Observation, params: LandmarkParams | None = None
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The clip's time, transport speed and grip aperture, as the landmarks are measured.

    The wrist's low-passed speed and the low-passed tip-to-tip distance of
    the digit markers over the whole clip (``obs.clip_time``,
    ``obs.clip_raw``); an observation without them uses its scored span's
    unfiltered markers (``obs.raw``), and one without those its aperture
    ``g`` plus the marker separation, as
    :func:`~perception.landmarks.observed_landmarks` does.

    Parameters
    ----------
    obs : Observation
        The demonstration.
    params : LandmarkParams, optional
        The filter (default: the landmarks' own).

    Returns
    -------
    time : (T,) array
        s, on the observation's clock.
    speed : (T,) array
        Wrist speed, m/s (NaN where lost).
    aperture : (T,) array
        Grip aperture, m (NaN where lost).
    """
    params = LandmarkParams() if params is None else params
    time, raw = getattr(obs, "clip_time", None), getattr(obs, "clip_raw", None)
    if time is None or raw is None:
        r = getattr(obs, "raw", None) or {}
        time = obs.time
        if not all(k in r for k in ("wrist", "finger", "thumb")):
            return (np.asarray(time, dtype=float), params.speed_of(time, obs.wrist),
                    params.lowpass(time, obs.g + obs.marker_separation))
        raw = np.stack([r[k] for k in ("wrist", "finger", "thumb")], axis=1)
    time, raw = np.asarray(time, dtype=float), np.asarray(raw, dtype=float)
    return (time, params.speed_of(time, raw[:, 0]),
            params.lowpass(time, np.linalg.norm(raw[:, 1] - raw[:, 2], axis=1)))


def kinematics_title(rec: Recognition) -> str:
    """``clip: verdict (kind), familiarity 0.00``: the figure's title.

    The kind is that of an ``abnormal`` verdict; without a verdict (models
    without calibrations) the winner is named instead.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    """
    d = rec.decision
    verdict = d.verdict or f"no verdict (winner {rec.winner})"
    detail = rec.verdict_detail if d.verdict == "abnormal" else None
    if detail:
        verdict = f"{verdict} ({detail})"
    fam = "n/a" if not math.isfinite(d.familiarity) else f"{d.familiarity:.2f}"
    return f"{rec.clip}: {verdict}, familiarity {fam}"


def time_axis(rec: Recognition) -> tuple[float, str]:
    """The figure's clock: what to add to the observation's times, and the axis label.

    The recording's own clock where the recognition knows it
    (:attr:`~perception.recognition.result.Recognition.time_origin`: a
    motion-capture file's time column or first sample, as ``landmarks``'
    ``onset_time`` and ``end_time``); else the observation's, from the scored
    movement's start, named as such.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    """
    origin = getattr(rec, "time_origin", math.nan)
    if _finite(origin):
        return float(origin), "time on the recording's clock (s)"
    return 0.0, "time from the scored movement's start (s)"


def transport_label(rec: Recognition) -> str:
    """What the speed curve is the speed of: ``wrist``, or ``grip midpoint`` where the
    wrist was not recorded but placed behind the grip
    (:attr:`~perception.recognition.result.Recognition.transport_point`).

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    """
    return getattr(rec, "transport_point", "wrist")


def _at(lm: Landmarks, share: float) -> float:
    """The clock time of a share of the movement (NaN where any part is)."""
    return lm.onset_time + share * lm.movement_time


def _finite(*values: float) -> bool:
    return all(v is not None and math.isfinite(v) for v in values)


def _note(ax: Axes, x: float, y: float, text: str, colour: str, dy: float = 8.0):
    """A value beside a mark, a little above it (the annotation)."""
    return ax.annotate(text, (x, y), xytext=(6, dy), textcoords="offset points", fontsize=LEGEND_PT,
                color=colour, parse_math=False)


def _layout() -> tuple[Figure, np.ndarray]:
    """The empty figure: two panels sharing the time axis."""
    from matplotlib.figure import Figure

    width, height = SIZE
    fig = Figure(figsize=SIZE)
    new_canvas(fig)
    return fig, fig.subplots(2, 1, sharex=True, gridspec_kw=dict(
        left=LEFT / width, right=1 - RIGHT / width, bottom=BOTTOM / height,
        top=1 - TOP / height, hspace=GAP / ((height - BOTTOM - TOP - GAP) / 2)))


def kinematics_figure(rec: Recognition, *, reuse: bool = False,
                      traces: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> Figure:
    """The trial's transport speed and grip aperture with their landmarks.

    Above, the transport's speed (mm/s; labelled for what it is: the
    wrist's, or the grip midpoint's where the wrist was synthesised from the
    grip, :func:`transport_label`); below, the grip aperture (mm); over the
    whole clip, on the recording's clock where it is known, else from the
    scored movement's start, the axis label saying which
    (:func:`time_axis`). The movement, onset to end,
    is shaded and bounded by dashed lines across both panels (the bound's
    speed, 5 % of the peak, dotted); the peak speed and the MGA are dots on
    their curves, labelled with their values, the grip's start to open a
    triangle. A landmark that could not be measured (NaN) is not drawn. The
    title gives the clip, its verdict (with the kind of an abnormal one) and
    the familiarity.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    reuse : bool
        Draw on this thread's kept figure of this kind, valid until the next
        such call (the reports: :mod:`perception.report.canvas`); default a
        new figure.
    traces : tuple of array, optional
        The clip's :func:`kinematic_traces` by its rules' landmark filter, if
        already made (the clip report's, for its JSON too).
    """
    m = _marks(rec, traces)
    if not reuse:
        fig, axes = _layout()
        _draw(fig, axes, m)
        return fig
    if not len(m.time):  # limits found from the marks: drawn afresh on the emptied figure
        fig, axes = kept_figure("kinematics", _layout)
        legend = _draw(fig, axes, m)["legend"]
        quicker_legend(legend)  # a new legend on the kept figure, laid out once a draw
        return fig
    # the figure of this trial's marks kept with them: moved to this trial's values (a
    # trial's marks were a fifth of its figures' building)
    fig, drawn = kept_figure(("kinematics marks", *m.shape), lambda: _kept_layout(m),
                             clear=False)
    if drawn["marks"] is not m:
        _update(fig, drawn, m)
    return fig


@dataclasses.dataclass(frozen=True, eq=False)
class _Marks:
    """What a trial's kinematics figure shows: its curves (on the figure's clock, mm/s and
    mm), its landmarks' marks (None: not measured) and texts, its limits."""

    time: np.ndarray
    speed: np.ndarray
    aperture: np.ndarray
    point: str
    xlabel: str
    title: str
    span: tuple[float, float] | None
    bounds: tuple[tuple[float, str], ...]
    #: the bound's speed (a share of the peak), mm/s, and its legend entry
    bound: tuple[float, str] | None
    peak: tuple[float, float] | None
    #: where the grip starts to open, mm, and its legend entry
    opening: tuple[float, float, str] | None
    mga: tuple[float, float] | None
    ylims: tuple[tuple[float, float], tuple[float, float]]

    @property
    def shape(self) -> tuple:
        """What the figure's artists and their order depend on: which marks, the axis label."""
        return (self.point, self.span is not None, tuple(n for _, n in self.bounds),
                self.bound is not None, self.peak is not None, self.opening is not None,
                self.mga is not None)


def _marks(rec: Recognition, traces: tuple | None = None) -> _Marks:
    """The trial's curves and landmarks, as :func:`kinematics_figure` draws them (its
    :func:`kinematic_traces`, if made)."""
    lm = rec.landmarks[0]
    params = rec.rules.landmarks  # the definitions its landmarks were measured by
    time, speed, aperture = (kinematic_traces(rec.observation, params) if traces is None
                             else traces)
    origin, xlabel = time_axis(rec)
    time = time + origin
    lm = dataclasses.replace(lm, onset_time=lm.onset_time + origin,
                             end_time=lm.end_time + origin)
    on, end = lm.onset_time, lm.end_time
    bound = None
    if _finite(lm.peak_speed):
        bound = (params.threshold * lm.peak_speed * MM, f"{params.threshold:.0%} of the peak speed")
    t_peak, t_open, t_mga = (_at(lm, lm.peak_speed_time), _at(lm, lm.opening_time),
                             _at(lm, lm.mga_time))
    seen = np.isfinite(aperture)
    opening = None
    if _finite(t_open) and seen.any():
        opening = (t_open, float(np.interp(t_open, time[seen], aperture[seen])) * MM,
                   f"opening starts ({lm.opening_time:.0%} of the movement)")
    ylims = []
    for curve, least in ((speed, MIN_TOP[0]), (aperture, MIN_TOP[1])):
        # from 0, with room above the curve for the values; a still, closed hand looks it
        top = float(np.nanmax(curve)) * MM if np.isfinite(curve).any() else 0.0
        ylims.append((0.0, max(1.2 * top, least)))
    return _Marks(
        time, speed * MM, aperture * MM, transport_label(rec), xlabel, kinematics_title(rec),
        (on, end) if _finite(on, end) and end > on else None,
        tuple((t, name) for t, name in ((on, "onset"), (end, "end")) if _finite(t)), bound,
        (t_peak, lm.peak_speed * MM) if _finite(t_peak, lm.peak_speed) else None, opening,
        (t_mga, lm.mga * MM) if _finite(t_mga, lm.mga) else None, (ylims[0], ylims[1]))


def _kept_layout(m: _Marks) -> tuple[Figure, dict]:
    """A kept figure of ``m``'s marks: the empty figure, drawn with them."""
    fig, axes = _layout()
    return fig, _draw(fig, axes, m)


def _draw(fig: Figure, axes, m: _Marks) -> dict:
    """Build ``m``'s artists on the empty figure ``fig`` (its two panels ``axes``) and set
    their values (:func:`_update`, which sets every one: a new figure and a kept one
    moved to another trial are drawn by the one function); return them.

    The curves are built empty, the marks where ``m`` puts them (a figure with no
    samples finds its time axis from its marks as they are added), their texts empty.
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    top, grip = axes
    # the entries whose texts vary are labelled here too (matplotlib leaves out of a
    # legend a line that has none), and again by _update
    curves = [top.plot([], [], color=SPEED_COLOUR, lw=1.8, label=f"{m.point} speed")[0],
              grip.plot([], [], color=GRIP_COLOUR, lw=1.8, label="grip aperture")[0]]
    drawn: dict = {"curves": curves}
    handles = list(curves)
    if m.span is not None:
        drawn["spans"] = [ax.axvspan(*m.span, color=SHADE_COLOUR, alpha=0.12, lw=0, zorder=0)
                          for ax in (top, grip)]
        handles.append(Patch(color=SHADE_COLOUR, alpha=0.25, label="movement"))
    drawn["bounds"] = []
    for t, name in m.bounds:
        lines = [ax.axvline(t, color=BOUND_COLOUR, ls="--", lw=1.0, zorder=1.5, gid=name)
                 for ax in (top, grip)]
        # outside the movement, so that the two never overlap however short it is
        note = top.annotate("", (t, 1.0), xycoords=("data", "axes fraction"),
                            xytext=(-2 if name == "onset" else 2, 3),
                            textcoords="offset points",
                            ha="right" if name == "onset" else "left", va="bottom",
                            fontsize=LEGEND_PT, color=BOUND_COLOUR)
        drawn["bounds"].append((lines, note))
    if m.bounds:
        handles.append(Line2D([], [], color=BOUND_COLOUR, ls="--", lw=1.0,
                              label="onset / end"))
    if m.bound is not None:
        drawn["bound"] = top.axhline(m.bound[0], color=BOUND_COLOUR, ls=":", lw=0.9, zorder=1.5,
                                     gid="bound")
        drawn["bound entry"] = len(handles)
        handles.append(Line2D([], [], color=BOUND_COLOUR, ls=":", lw=0.9, label=m.bound[1]))
    if m.peak is not None:
        t, y = m.peak
        handles += top.plot([t], [y], "o", color=SPEED_COLOUR, ms=7, mec="k", mew=0.8,
                            zorder=3, gid="peak_speed", label="peak speed")
        drawn["peak"] = handles[-1], _note(top, t, y, "", SPEED_COLOUR, dy=-4.0)
    if m.opening is not None:
        t, y, label = m.opening
        handles += grip.plot([t], [y], "^", color=GRIP_COLOUR, ms=8, mfc="w", mew=1.5,
                             zorder=3, gid="opening", label=label)
        drawn["opening"], drawn["opening entry"] = handles[-1], len(handles) - 1
    if m.mga is not None:
        t, y = m.mga
        handles += grip.plot([t], [y], "o", color=GRIP_COLOUR, ms=7, mec="k", mew=0.8,
                             zorder=3, gid="mga", label="MGA (maximum grip aperture)")
        drawn["mga"] = handles[-1], _note(grip, t, y, "", GRIP_COLOUR)
    for ax in (top, grip):
        ax.grid(True, color="0.92", lw=0.6, zorder=0)
    drawn["legend"] = _legend(fig, handles, "lower center", ncols=4, frameon=False)
    _update(fig, drawn, m)
    return drawn


def _update(fig: Figure, drawn: dict, m: _Marks) -> None:
    """Move the artists of :func:`_draw` (marks of the same shape) to ``m``: every value
    the figure shows (curves, marks, notes, legend texts, labels, limits, title)."""
    drawn["marks"] = m
    top, grip = fig.axes
    texts = drawn["legend"].get_texts()
    for line, y in zip(drawn["curves"], (m.speed, m.aperture)):
        line.set_data(m.time, y)
    speed = f"{m.point} speed"
    drawn["curves"][0].set_label(speed)
    texts[0].set_text(printable(speed))
    if m.span is not None:
        on, end = m.span
        for span in drawn["spans"]:  # as axvspan makes it: from (on, 0), end - on wide
            span.set_xy((on, 0))
            span.set_width(end - on)
    for (t, name), (lines, note) in zip(m.bounds, drawn["bounds"]):
        for line in lines:
            line.set_xdata([t, t])
        note.xy = (t, 1.0)
        note.set_text(_bound_text(t, name))
    if m.bound is not None:
        drawn["bound"].set_ydata([m.bound[0], m.bound[0]])
        texts[drawn["bound entry"]].set_text(printable(m.bound[1]))
    if m.peak is not None:
        (marker, note), (t, y) = drawn["peak"], m.peak
        marker.set_data([t], [y])
        note.xy = (t, y)
        note.set_text(_peak_text(y))
    if m.opening is not None:
        t, y, label = m.opening
        drawn["opening"].set_data([t], [y])
        drawn["opening"].set_label(label)
        texts[drawn["opening entry"]].set_text(printable(label))
    if m.mga is not None:
        (marker, note), (t, y) = drawn["mga"], m.mga
        marker.set_data([t], [y])
        note.xy = (t, y)
        note.set_text(_mga_text(y))
    for ax, label, ylim in ((top, f"{m.point} speed (mm/s)", m.ylims[0]),
                            (grip, "grip aperture (mm)", m.ylims[1])):
        ax.set_ylabel(label)
        ax.set_ylim(*ylim)
    if len(m.time):
        grip.set_xlim(float(np.nanmin(m.time)), float(np.nanmax(m.time)))
    grip.set_xlabel(m.xlabel)
    _title(fig, m.title)


def _bound_text(t: float, name: str) -> str:
    return f"{name} {t:.2f} s"


def _peak_text(y: float) -> str:
    return f"peak {y:.0f} mm/s"


def _mga_text(y: float) -> str:
    return f"MGA {y:.0f} mm"
