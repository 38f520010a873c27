"""Report figures (thesis chapter 5) as matplotlib ``Figure`` s, built on request.

Per clip: every model's confidence and log-likelihood
(:func:`confidence_figure`, also :meth:`Recognition.plot()
<perception.recognition.result.Recognition.plot>`) and the demonstration
against the reference grasp model's own movement (:func:`paths_figure`,
Figs. 5.5-5.7). Per batch: grip aperture per condition against the model's
(:func:`aperture_figure`, Fig. 5.4d), the reference model's confidence on one
clip per condition (:func:`confidence_single_figure`, Fig. 5.8a) and on
every clip (:func:`confidence_all_figure`, Fig. 5.8b), and mean ± SD per
condition at select points (:func:`condition_figure`, Fig. 5.8c).

The thesis's figure numbers are in these docstrings and in the captions of
``report.html``, not in the figures' titles. Each is a
:class:`matplotlib.figure.Figure` on an Agg canvas, never through pyplot (no
global figure registry; safe in worker processes); :func:`write_figure` saves
one as PNG, SVG or PDF (:data:`FIGURE_FORMATS`). matplotlib is imported when the
first figure is drawn, not with this module: it costs about 0.4 s, which
``import perception`` and ``recognize --no-figures`` do not pay. Texts from
the outside world (clip, model and condition names) are drawn as they are: a
``$`` is a dollar, not mathtext, and undecodable bytes show as ``\\xNN``.
Confidence is drawn in cm (weighted), ×100 of its value in the files.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from perception.io.atomic import save_figure, write_bytes
from perception.io.names import printable
from perception.report.canvas import kept_figure, png_encoder

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.legend import Legend

    from perception.recognition.result import Recognition
    from perception.report.clip import ClipSummary

__all__ = ["DPI", "FIGURE_FORMATS", "FigureFiles", "aperture_figure", "condition_colour",
           "condition_figure", "confidence_all_figure", "confidence_figure",
           "confidence_single_figure", "paths_figure", "write_figure"]

#: The formats :func:`write_figure` writes, the first the default; and its default resolution.
FIGURE_FORMATS = ("png", "svg", "pdf")
DPI = 120
#: Vector text: SVG text stays text (editable, searchable), PDF fonts are TrueType (Type 42),
#: which journals' checks take where they refuse Type 3.
_VECTOR_TEXT = {"svg.fonttype": "none", "pdf.fonttype": 42, "svg.hashsalt": "hammer-mv"}


CM = 100.0
#: Colours of the chapter 5 conditions; others take the next free colour.
CONDITION_COLOURS = {"normal": "C0", "delayed": "C1", "open-close-open": "C3", "reach": "C2",
                     "unlabelled": "0.4"}
_SPARE = ("C4", "C5", "C6", "C7", "C8", "C9")
#: Line widths of the models in the confidence figure: the winner, the others.
THICK, THIN = 2.6, 1.2
#: Legend font size, points.
LEGEND_PT = 9.0
TIME = "time since onset (s)"
MOVEMENT_TIME = "movement time (%)"
#: Error bars of Fig. 5.8c: at this many evenly spaced phases.
SD_POINTS = 11


def condition_colour(condition: str, seen: Sequence[str] = ()) -> str:
    """The colour of a condition (a fixed one for the chapter 5 conditions).

    Parameters
    ----------
    condition : str
        Condition name.
    seen : sequence of str
        Conditions in the figure, in order (others get spare colours in this order).
    """
    if condition in CONDITION_COLOURS:
        return CONDITION_COLOURS[condition]
    others = [c for c in dict.fromkeys(seen) if c not in CONDITION_COLOURS]
    i = others.index(condition) if condition in others else len(others)
    return _SPARE[i % len(_SPARE)]


# -- the canvas ---------------------------------------------------------------------
#: Margins around the panels, inches: left of the first (tick labels and the y
#: label), between two (the next one's), right, below (x ticks and label) and
#: above (a panel's title; with the figure's title).
LEFT, GAP, RIGHT, BOTTOM, TOP, TOP_TITLED = 0.85, 0.85, 0.2, 0.55, 0.35, 0.7
#: Height of one row of a legend below the panels (9 pt text and its spacing), inches.
LEGEND_ROW = 0.21


def _figure(size: tuple[float, float], panels: int = 1, *, titled: bool = False,
            legend_rows: int = 0, keep: str | None = None) -> tuple[Figure, np.ndarray]:
    """A figure on the report's Agg canvas with ``panels`` axes side by side.

    The margins are fixed (:data:`LEFT`, ...) rather than found by
    matplotlib's constrained layout, which measures every text once more
    before drawing: a third of a figure's drawing time, 0.1 s a figure. A
    titled figure leaves room for its title; ``legend_rows`` rows of a legend
    below the panels (its title one of them) get room there. With ``keep``
    (a figure kind), the figure is this thread's kept one of that kind and
    layout, emptied (:func:`~perception.report.canvas.kept_figure`): for a
    figure drawn and saved at once, never one handed to a caller.
    """
    def build() -> tuple[Figure, np.ndarray]:
        from matplotlib.figure import Figure

        from perception.report.canvas import new_canvas

        width, height = size
        fig = Figure(figsize=size)
        new_canvas(fig)
        panel = (width - LEFT - RIGHT - GAP * (panels - 1)) / panels
        bottom = BOTTOM + (legend_rows * LEGEND_ROW + 0.1 if legend_rows else 0.0)
        axes = fig.subplots(1, panels, squeeze=False, gridspec_kw=dict(
            left=LEFT / width, right=1 - RIGHT / width, wspace=GAP / panel,
            bottom=bottom / height, top=1 - (TOP_TITLED if titled else TOP) / height))
        return fig, axes[0]

    if keep is None:
        return build()
    return kept_figure((keep, size, panels, titled, legend_rows), build)


def _panel(ax: Axes, title: str, xlabel: str, ylabel: str, *, zero: bool = False) -> None:
    if zero:  # under the lines, over any band
        ax.axhline(0.0, color="0.7", lw=0.6, zorder=1.5)
    # names hold "$" (text, not mathtext) and undecodable bytes (escaped); the title's
    # height given (where matplotlib would find it, above panels whose ticks are below)
    # spares measuring every tick label for it at each draw
    ax.set_title(printable(title), parse_math=False, y=1.0)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(printable(ylabel), parse_math=False)


def _legend(where: Axes | Figure, handles: list, loc: str = "best", **kwargs) -> Legend:
    """A legend of ``handles`` (lines), each labelled with its label as text.

    The lines are named rather than found by their labels: matplotlib leaves
    out a label starting with ``_``, and a clip's name may.
    """
    legend = where.legend(handles=handles, labels=[printable(h.get_label()) for h in handles],
                          loc=loc, fontsize=LEGEND_PT, title_fontsize=LEGEND_PT, **kwargs)
    for text in (*legend.get_texts(), legend.get_title()):
        text.set_parse_math(False)
    return legend


def _title(fig: Figure, title: str) -> None:
    fig.suptitle(printable(title), parse_math=False)


def _verdict_line(rec: Recognition) -> str:
    d = rec.decision
    # a winner whose kind contradicts the verdict (a reach model on a normal grasp) is
    # the closest model at the clip's own scale, not what the verdict is about
    winner = "closest model" if getattr(rec, "winner_note", None) else "winner"
    if d.verdict is None:
        return f"{winner} {rec.winner} ({rec.rule} rule)"
    return (f"verdict {d.verdict} (familiarity {d.familiarity:.2f}, margin {d.margin:.1f}); "
            f"{winner} {rec.winner} ({rec.rule} rule)")


# -- one clip ---------------------------------------------------------------------
def confidence_figure(rec: Recognition, *, reuse: bool = False) -> Figure:
    """Confidence profiles of every model (thesis rule) and the log-likelihood.

    Left, the thesis rule's confidence C; right, the cumulative
    log-likelihood; a line per model in both (grasp models solid, reach
    dashed, the winner thick) and one legend below them.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    reuse : bool
        Draw on this thread's kept figure of this kind, valid until the next
        such call (the reports: see :mod:`perception.report.canvas`); default
        a new figure.
    """
    if reuse:  # its lines and legend kept: the same models
        key = ("confidence lines", tuple(rec.names), tuple(rec.kinds))
        fig, drawn = kept_figure(key, lambda: _confidence_layout(rec.names, rec.kinds),
                                 clear=False)
    else:
        fig, drawn = _confidence_layout(rec.names, rec.kinds)
    return _confidence_data((fig, *drawn), rec)


def _confidence_layout(names: Sequence[str], kinds: Sequence[str]
                       ) -> tuple[Figure, tuple[list, list, object]]:
    """The confidence figure without data: the panels, a line per model in each, the legend."""
    columns = min(len(names), 5)
    fig, (conf, ll) = _figure((12, 5), 2, titled=True, legend_rows=1 - (-len(names) // columns))
    styles = {"grasp": "-", "reach": "--"}
    lines = []
    for k, (name, kind) in enumerate(zip(names, kinds)):
        look = dict(color=f"C{k % 10}", lw=THIN, ls=styles.get(kind, "-"), label=name)
        lines.append((*conf.plot([], [], **look), *ll.plot([], [], **look)))
    _panel(conf, "thesis rule: confidence C (eqs. 5.6-5.8)", TIME, "C (cm, weighted)",
           zero=True)
    _panel(ll, "likelihood rule: cumulative log-likelihood", TIME, "log-likelihood", zero=True)
    legend = _legend(fig, [c for c, _ in lines], "lower center", ncols=columns,
                     title="grasp models solid, reach dashed; the winner thick", frameon=False)
    return fig, (lines, legend.legend_handles)


def _confidence_data(drawn: tuple[Figure, list, list], rec: Recognition) -> Figure:
    """Draw ``rec`` on a confidence figure's lines: its curves, its winner thick, its title."""
    fig, lines, keys = drawn
    for (conf, ll), key, name, c, l in zip(lines, keys, rec.names, rec.confidence,
                                            rec.log_likelihood):
        width = THICK if name == rec.winner else THIN
        for line, y in ((conf, c * CM), (ll, l)):
            line.set_data(rec.time, y)
            line.set_linewidth(width)
        key.set_linewidth(width)
    for ax in fig.axes:  # the limits of these curves, as a new figure's would be
        ax.relim()
        ax.autoscale_view()
    _title(fig, f"{rec.clip}: {_verdict_line(rec)}")
    return fig


def paths_figure(rec: Recognition, model: str | None = None, *, reuse: bool = False
                 ) -> Figure:
    """The demonstration against a grasp model's own movement (thesis Figs. 5.5-5.7).

    Left, the observed wrist, finger and thumb paths and the model's own
    noise-free movement from the same start; right, the grip aperture over
    time: observed, the model's own, and the model's one-step predictions.
    A wrist that was not recorded but placed behind the grip (a
    motion-capture reach without a wrist marker:
    :attr:`~perception.recognition.result.Recognition.wrist_synthesised`) is
    not drawn as observed: it would be the grip midpoint's path, moved; the
    panel's title says so.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    model : str, optional
        Model drawn (default: the reference grasp model, the grasp model with
        the highest log-likelihood; the winner if there is no grasp model).
    reuse : bool
        Draw on this thread's kept figure of this kind (as
        :func:`confidence_figure`).
    """
    model = model or rec.reference_model or rec.winner
    rec.names.index(model)  # a model it was not scored on: ValueError
    placed = bool(getattr(rec, "wrist_synthesised", False))
    if reuse:  # its lines, note and legends kept: the same model, the wrist drawn or not
        fig, lines = kept_figure(("paths lines", model, placed),
                                 lambda: _paths_layout(model, placed), clear=False)
    else:
        fig, lines = _paths_layout(model, placed)
    return _paths_data(fig, lines, rec, model, placed)


def _paths_layout(model: str, placed: bool) -> tuple[Figure, list]:
    """The paths figure without data: its lines (paths panel, then grip), note, legends."""
    fig, (paths, grip) = _figure((12, 5.5), 2, titled=True)
    for key, colour in (("finger", "g"), ("thumb", "r"), ("wrist", "b")):
        if not (key == "wrist" and placed):
            paths.plot([], [], "-", color=colour, lw=1.8, label=f"{key} observed")
        paths.plot([], [], "--", color=colour, lw=1.5, label=f"{key}, {model}")
    paths.plot([], [], "-", color="y", lw=2.0, label="object")
    paths.set_aspect("equal", adjustable="datalim")
    _panel(paths, f"paths: observed (solid) and {model}'s own movement (dashed)", "x (m)",
           "y (m), toward the object")
    if placed:  # under the title, in its own words (a title is printed, newlines escaped)
        paths.annotate("wrist not recorded (placed behind the grip): not drawn", (0.5, 1.0),
                       xycoords="axes fraction", xytext=(0, -12), textcoords="offset points",
                       ha="center", va="top", fontsize=LEGEND_PT, color="0.3", gid="no-wrist")
    _legend(paths, paths.get_lines(), ncols=2)
    grip.plot([], [], "-", color="k", lw=2.0, label="observed")
    grip.plot([], [], "--", color="k", lw=1.5, label=f"{model}'s own movement")
    grip.plot([], [], ":", color="0.45", lw=1.2, label=f"{model}, one step ahead")
    _panel(grip, "grip aperture", TIME, "grip aperture (cm)")
    _legend(grip, grip.get_lines())
    return fig, [*paths.get_lines(), *grip.get_lines()]


def _paths_data(fig: Figure, lines: list, rec: Recognition, model: str, placed: bool
                ) -> Figure:
    """Draw ``rec`` on a paths figure's lines (in :func:`_paths_layout`'s order) and title."""
    # the movement as it was scored (at the repertoire's scale, where the model's own is)
    obs, own = rec.scored_movement, rec.nominal(model)
    data = []
    for key in ("finger", "thumb", "wrist"):
        seen, plan = getattr(obs, key), own[key]
        if not (key == "wrist" and placed):
            data.append((seen[:, 0], seen[:, 1]))
        data.append((plan[:, 0], plan[:, 1]))
    circle, rad = np.linspace(0, 2 * np.pi, 100), obs.object_diameter / 2
    data.append((rad * np.cos(circle), rad * np.sin(circle)))
    own_g = np.linalg.norm(own["finger"] - own["thumb"], axis=1)
    data += [(rec.time, obs.g * CM), (rec.time, own_g * CM),
             (rec.time, rec.predicted_g[rec.names.index(model)] * CM)]
    for line, (x, y) in zip(lines, data, strict=True):
        line.set_data(x, y)
    for ax in fig.axes:  # the limits of these curves, as a new figure's would be
        ax.relim()
        ax.autoscale_view()
    _title(fig, f"{rec.clip}: {_verdict_line(rec)}")
    return fig


# -- a batch ----------------------------------------------------------------------
def _n_label(cond: str, g: pd.DataFrame) -> str:
    return f"{cond} (n={int(g['n'].iloc[0])})"


def condition_figure(profiles: pd.DataFrame, model: str) -> Figure:
    """Mean ± SD confidence per condition at select points (thesis Fig. 5.8c).

    The total confidence, and its transport and grip terms when
    ``profiles`` has them (``transport_mean``, ``grip_mean``, …): a mean
    curve per condition with SD bars at :data:`SD_POINTS` evenly spaced
    phases, the legend in the first panel.

    Parameters
    ----------
    profiles : pandas.DataFrame
        From :func:`~perception.report.conditions.condition_profiles`.
    model : str
        The model profiled (for the title).
    """
    parts = [("", "confidence C")]
    if "transport_mean" in profiles.columns:
        parts += [("transport_", "transport term"), ("grip_", "grip term")]
    conds = list(dict.fromkeys(profiles["condition"]))
    fig, axes = _figure((5.2 * len(parts), 4.8), len(parts), titled=True)
    for ax, (prefix, title) in zip(axes, parts):
        means = []
        for cond, g in profiles.groupby("condition", sort=False):
            colour = condition_colour(cond, conds)
            x = g["phase"].to_numpy() * 100
            mean, sd = g[f"{prefix}mean"].to_numpy() * CM, g[f"{prefix}sd"].to_numpy() * CM
            means += ax.plot(x, mean, color=colour, lw=1.8, label=_n_label(cond, g))
            at = np.unique(np.round(np.linspace(0, len(g) - 1, SD_POINTS)).astype(int))
            ax.errorbar(x[at], mean[at], yerr=sd[at], fmt="none", ecolor=colour, elinewidth=1.0,
                        capsize=3.0, capthick=1.0)
        _panel(ax, f"{title}: mean ± SD", MOVEMENT_TIME, f"{title} (cm, weighted)", zero=True)
        if ax is axes[0]:
            _legend(ax, means)
    _title(fig, f"{model}'s confidence by condition")
    return fig


def aperture_figure(profiles: pd.DataFrame, model: pd.DataFrame | None = None,
                    model_name: str = "") -> Figure:
    """Grip aperture per condition, mean ± SD, against the model's (thesis Fig. 5.4d).

    A mean curve per condition over a band of ± 1 SD; the model's own
    aperture dashed black over a grey band.

    Parameters
    ----------
    profiles : pandas.DataFrame
        From :func:`~perception.report.conditions.aperture_profiles`
        (condition, phase, mean, sd, n; m).
    model : pandas.DataFrame, optional
        The model's own aperture (phase, mean, sd; m), drawn dashed.
    model_name : str
        The model's name, for the legend.
    """
    conds = list(dict.fromkeys(profiles["condition"]))
    curves = [(g, condition_colour(cond, conds), 0.2, "-", _n_label(cond, g))
              for cond, g in profiles.groupby("condition", sort=False)]
    if model is not None and len(model):
        curves.append((model, "k", 0.12, "--", f"model {model_name}"))
    fig, (ax,) = _figure((7.5, 5))
    for g, colour, alpha, style, label in curves:
        x, mean, sd = (g[c].to_numpy(dtype=float) * 100 for c in ("phase", "mean", "sd"))
        ax.fill_between(x, mean - sd, mean + sd, color=colour, alpha=alpha, lw=0)
        ax.plot(x, mean, style, color=colour, lw=1.8, label=label)
    _panel(ax, "grip aperture, mean ± SD", MOVEMENT_TIME, "grip aperture (cm)")
    _legend(ax, ax.get_lines())
    return fig


def _confidence_panel(model: str, title: str,
                      lines: Sequence[tuple[ClipSummary, str, float, str | None]]) -> Figure:
    """One panel of ``model``'s confidence: a line per (clip, colour, width, label)."""
    fig, (ax,) = _figure((7.5, 5))
    labelled = []
    for rec, colour, width, label in lines:
        (line,) = ax.plot(rec.time, rec.confidence[rec.index(model)] * CM, color=colour,
                          lw=width, label=label)
        if label is not None:
            labelled.append(line)
    _panel(ax, title, TIME, f"C of {model} (cm, weighted)", zero=True)
    _legend(ax, labelled)
    return fig


def confidence_single_figure(clips: Sequence[ClipSummary], conditions: Sequence[str],
                             model: str) -> Figure:
    """The model's confidence on one clip per condition (thesis Fig. 5.8a).

    Parameters
    ----------
    clips : sequence of ClipSummary
        One clip per condition.
    conditions : sequence of str
        Their conditions.
    model : str
        The model whose confidence is drawn.
    """
    return _confidence_panel(model, "one clip per condition", [
        (rec, condition_colour(cond, conditions), 1.8, f"{cond}: {rec.clip}")
        for rec, cond in zip(clips, conditions)])


def confidence_all_figure(clips: Sequence[ClipSummary], conditions: Sequence[str],
                          model: str) -> Figure:
    """The model's confidence on every clip, coloured by condition (thesis Fig. 5.8b).

    One thin line a clip, in the clips' order (one ``LineCollection``); the
    legend names each condition once.

    Parameters
    ----------
    clips : sequence of ClipSummary
        Scored clips.
    conditions : sequence of str
        Their conditions.
    model : str
        The model whose confidence is drawn.
    """
    from matplotlib.collections import LineCollection
    from matplotlib.lines import Line2D

    fig, (ax,) = _figure((7.5, 5))
    colours = [condition_colour(cond, conditions) for cond in conditions]
    # one artist for every clip's line, in the clips' order: a Line2D a clip cost a
    # batch of 6,000 clips 3.6 s to build and 2 s to draw
    ax.add_collection(LineCollection(
        [np.column_stack([rec.time, rec.confidence[rec.index(model)] * CM]) for rec in clips],
        colors=colours, linewidths=1.0))
    ax.autoscale_view()
    _panel(ax, f"every clip ({len(clips)})", TIME, f"C of {model} (cm, weighted)", zero=True)
    _legend(ax, [Line2D([], [], color=condition_colour(cond, conditions), lw=1.0, label=cond)
                 for cond in dict.fromkeys(conditions)])
    return fig


def _checked(fmt: str, dpi: int) -> None:
    if fmt not in FIGURE_FORMATS:
        raise ValueError(f"figure format must be one of {', '.join(FIGURE_FORMATS)}, not {fmt!r}")
    if not (isinstance(dpi, int | np.integer) and dpi > 0):
        raise ValueError(f"dpi must be a positive whole number, not {dpi!r}")


def _drawn_png(fig: Figure, dpi: int) -> Callable[[], bytes]:
    """``fig`` drawn now, and what encodes its PNG
    (:func:`~perception.report.canvas.png_encoder`)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Glyph .* missing from",
                                category=UserWarning)  # drawn as a box, as save_figure
        return png_encoder(fig, int(dpi))


def write_figure(fig: Figure, path_stem: str | Path, fmt: str = "png", dpi: int = DPI) -> Path:
    """Save ``fig`` as ``<path_stem>.<fmt>``, atomically: PNG at ``dpi``, or vector SVG or PDF.

    SVG and PDF hold the lines, bands and text as vectors (SVG as text,
    editable; PDF with TrueType fonts), with no embedded image; ``dpi`` sets
    only their nominal size in pixels.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path_stem : str or Path
        The file's path without its format's suffix (a clip's stem may hold dots).
    fmt : str
        ``png``, ``svg`` or ``pdf`` (:data:`FIGURE_FORMATS`).
    dpi : int
        Dots per inch, positive.

    Returns
    -------
    Path
        The file written.
    """
    from matplotlib import rc_context

    _checked(fmt, dpi)
    path = Path(f"{path_stem}.{fmt}")
    if fmt == "png":  # encoded here: half Pillow's time (perception.report.canvas)
        return write_bytes(path, _drawn_png(fig, dpi)())
    with rc_context(_VECTOR_TEXT):
        return save_figure(path, fig, dpi=int(dpi))


class FigureFiles:
    """Figures written one after another as :func:`write_figure` writes them, each PNG
    encoded while the caller draws the next.

    A PNG's encoding (NumPy and zlib, which let other threads run: about a
    tenth of a report figure's time) runs in a thread of its own from the
    moment its figure is drawn; the file is written by the caller's thread
    when the next figure is given, or at :meth:`close`. Drawing stays in the
    caller's thread (matplotlib's figures are not shared between threads);
    the encoding thread imports nothing (two threads importing at once can
    fail) and writes no file (writing reads the process's umask by setting
    it: two threads at once could leave it 0). SVG and PDF are written at
    once. A context manager: leaving it writes what is pending (not after an
    error).

    Parameters
    ----------
    fmt : str
        ``png``, ``svg`` or ``pdf`` (:data:`FIGURE_FORMATS`).
    dpi : int
        Dots per inch, positive.
    """

    def __init__(self, fmt: str = "png", dpi: int = DPI):
        _checked(fmt, dpi)
        self.fmt, self.dpi = fmt, int(dpi)
        # one encoding thread: its future carries the PNG's bytes or the error, raised
        # again in the caller's thread
        self._pool = ThreadPoolExecutor(1, thread_name_prefix="hammer-mv figure encoding")
        self._pending: tuple[Path, Future] | None = None

    def write(self, fig: Figure, path_stem: str | Path) -> Path:
        """Draw ``fig`` now and write it as ``<path_stem>.<fmt>`` (a PNG: by the next
        :meth:`write` or :meth:`close`).

        Parameters
        ----------
        fig : matplotlib.figure.Figure
            The figure; drawn before this returns, so that it may be emptied and
            drawn again (a kept figure: :func:`~perception.report.canvas.kept_figure`).
        path_stem : str or Path
            The file's path without its format's suffix.

        Returns
        -------
        Path
            The file's path (a PNG's written later).
        """
        if self.fmt != "png":
            self._finish()
            return write_figure(fig, path_stem, self.fmt, self.dpi)
        path = Path(f"{path_stem}.{self.fmt}")
        encode = _drawn_png(fig, self.dpi)  # while the last figure is encoded
        self._finish()
        self._pending = path, self._pool.submit(encode)
        return path

    def _finish(self) -> None:
        """Wait for the pending PNG and write it."""
        if self._pending is None:
            return
        path, encoded = self._pending
        self._pending = None
        write_bytes(path, encoded.result())

    def close(self) -> None:
        """Write the PNG still pending (waiting for its encoding)."""
        try:
            self._finish()
        finally:
            self._pool.shutdown()

    def __enter__(self) -> FigureFiles:
        return self

    def __exit__(self, kind, value, traceback) -> None:
        if kind is None:
            self.close()
        else:  # not written after an error
            self._pending = None
            self._pool.shutdown()
