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


def _note(ax: Axes, x: float, y: float, text: str, colour: str, dy: float = 8.0) -> None:
    """A value beside a mark, a little above it."""
    ax.annotate(text, (x, y), xytext=(6, dy), textcoords="offset points", fontsize=LEGEND_PT,
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


def kinematics_figure(rec: Recognition, *, reuse: bool = False) -> Figure:
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
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    lm = rec.landmarks[0]
    params = rec.rules.landmarks  # the definitions its landmarks were measured by
    time, speed, aperture = kinematic_traces(rec.observation, params)
    origin, xlabel = time_axis(rec)
    time = time + origin
    lm = dataclasses.replace(lm, onset_time=lm.onset_time + origin,
                             end_time=lm.end_time + origin)
    point = transport_label(rec)

    fig, (top, grip) = kept_figure("kinematics", _layout) if reuse else _layout()
    handles = [top.plot(time, speed * MM, color=SPEED_COLOUR, lw=1.8,
                        label=f"{point} speed")[0],
               grip.plot(time, aperture * MM, color=GRIP_COLOUR, lw=1.8,
                         label="grip aperture")[0]]

    on, end = lm.onset_time, lm.end_time
    if _finite(on, end) and end > on:
        for ax in (top, grip):
            ax.axvspan(on, end, color=SHADE_COLOUR, alpha=0.12, lw=0, zorder=0)
        handles.append(Patch(color=SHADE_COLOUR, alpha=0.25, label="movement"))
    bounds = [(t, name) for t, name in ((on, "onset"), (end, "end")) if _finite(t)]
    for t, name in bounds:
        for ax in (top, grip):
            ax.axvline(t, color=BOUND_COLOUR, ls="--", lw=1.0, zorder=1.5, gid=name)
        # outside the movement, so that the two never overlap however short it is
        top.annotate(f"{name} {t:.2f} s", (t, 1.0), xycoords=("data", "axes fraction"),
                     xytext=(-2 if name == "onset" else 2, 3), textcoords="offset points",
                     ha="right" if name == "onset" else "left", va="bottom",
                     fontsize=LEGEND_PT, color=BOUND_COLOUR)
    if bounds:
        handles.append(Line2D([], [], color=BOUND_COLOUR, ls="--", lw=1.0,
                              label="onset / end"))
    if _finite(lm.peak_speed):
        top.axhline(params.threshold * lm.peak_speed * MM, color=BOUND_COLOUR, ls=":", lw=0.9,
                    zorder=1.5, gid="bound")
        handles.append(Line2D([], [], color=BOUND_COLOUR, ls=":", lw=0.9,
                              label=f"{params.threshold:.0%} of the peak speed"))

    t_peak = _at(lm, lm.peak_speed_time)
    if _finite(t_peak, lm.peak_speed):
        y = lm.peak_speed * MM
        handles += top.plot([t_peak], [y], "o", color=SPEED_COLOUR, ms=7, mec="k", mew=0.8,
                            zorder=3, gid="peak_speed", label="peak speed")
        _note(top, t_peak, y, f"peak {y:.0f} mm/s", SPEED_COLOUR, dy=-4.0)
    t_open = _at(lm, lm.opening_time)
    seen = np.isfinite(aperture)
    if _finite(t_open) and seen.any():
        y = float(np.interp(t_open, time[seen], aperture[seen])) * MM
        handles += grip.plot([t_open], [y], "^", color=GRIP_COLOUR, ms=8, mfc="w", mew=1.5,
                             zorder=3, gid="opening",
                             label=f"opening starts ({lm.opening_time:.0%} of the movement)")
    t_mga = _at(lm, lm.mga_time)
    if _finite(t_mga, lm.mga):
        y = lm.mga * MM
        handles += grip.plot([t_mga], [y], "o", color=GRIP_COLOUR, ms=7, mec="k", mew=0.8,
                             zorder=3, gid="mga", label="MGA (maximum grip aperture)")
        _note(grip, t_mga, y, f"MGA {y:.0f} mm", GRIP_COLOUR)

    for ax, label, curve, least in ((top, f"{point} speed (mm/s)", speed, MIN_TOP[0]),
                                    (grip, "grip aperture (mm)", aperture, MIN_TOP[1])):
        ax.set_ylabel(label)
        ax.grid(True, color="0.92", lw=0.6, zorder=0)
        # from 0, with room above the curve for the values; a still, closed hand looks it
        peak = float(np.nanmax(curve)) * MM if np.isfinite(curve).any() else 0.0
        ax.set_ylim(0.0, max(1.2 * peak, least))
    if len(time):
        grip.set_xlim(float(np.nanmin(time)), float(np.nanmax(time)))
    grip.set_xlabel(xlabel)
    legend = _legend(fig, handles, "lower center", ncols=4, frameon=False)
    if reuse:  # a new legend on the kept figure, its boxes laid out once a draw
        quicker_legend(legend)
    _title(fig, kinematics_title(rec))
    return fig
