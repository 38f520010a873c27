"""Report figures (thesis chapter 5): confidence profiles (Fig. 5.8), predicted
against observed digit paths and grip aperture (Figs. 5.5-5.7), and mean ± SD
confidence per stimulus condition (Fig. 5.8c).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from minvar.plotting import new_figure
from perception.recognition.result import Recognition

__all__ = ["condition_figure", "confidence_figure", "paths_figure"]


def confidence_figure(rec: Recognition) -> Figure:
    """Confidence profiles of every model (thesis rule) and the log-likelihood.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    """
    fig, ax = new_figure(1, 2, size=(11, 4))
    styles = {"grasp": "-", "reach": "--"}
    for name, kind, c, ll in zip(rec.names, rec.kinds, rec.confidence, rec.log_likelihood):
        ax[0, 0].plot(rec.time, c * 100, styles.get(kind, "-"), label=name, lw=1.2)
        ax[0, 1].plot(rec.time, ll, styles.get(kind, "-"), label=name, lw=1.2)
    ax[0, 0].set_title("thesis rule: confidence C (eqs. 5.6-5.8)")
    ax[0, 0].set_ylabel("C (cm, weighted)")
    ax[0, 1].set_title(f"likelihood rule: cumulative log-likelihood (winner {rec.winner})")
    ax[0, 1].set_ylabel("log-likelihood")
    for a in ax[0]:
        a.set_xlabel("time since onset (s)")
        a.axhline(0, color="0.7", lw=0.6)
    ax[0, 0].legend(fontsize=7, ncol=2)
    fig.suptitle(rec.clip)
    return fig


def paths_figure(rec: Recognition, model: str | None = None) -> Figure:
    """Predicted against observed digit paths and grip aperture (thesis Figs. 5.5-5.7).

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    model : str, optional
        Model whose predictions are drawn (default: the winner).
    """
    model = model or rec.winner
    i = rec.names.index(model)
    obs = rec.observation
    fig, ax = new_figure(1, 2, size=(11, 4.5))
    a = ax[0, 0]
    a.plot(*obs.finger.T, "g-", lw=1.5, label="finger observed")
    a.plot(*obs.thumb.T, "r-", lw=1.5, label="thumb observed")
    a.plot(*obs.wrist.T, "b-", lw=1.5, label="wrist observed")
    a.plot(*rec.predicted["finger"][i].T, "g:", lw=1.5, label="finger predicted")
    a.plot(*rec.predicted["thumb"][i].T, "r:", lw=1.5, label="thumb predicted")
    a.plot(*rec.predicted["wrist"][i].T, "b:", lw=1.5, label="wrist predicted")
    circle = np.linspace(0, 2 * np.pi, 100)
    rad = obs.object_diameter / 2
    a.plot(rad * np.cos(circle), rad * np.sin(circle), "y-", lw=2, label="object")
    a.set_aspect("equal", adjustable="datalim")
    a.set_xlabel("x (m)")
    a.set_ylabel("y (m), toward the object")
    a.set_title(f"paths: observed vs {model}")
    a.legend(fontsize=7)
    b = ax[0, 1]
    b.plot(rec.time, obs.g * 100, "k-", label="observed")
    b.plot(rec.time, rec.predicted_g[i] * 100, "k:", label=f"predicted ({model})")
    b.set_xlabel("time since onset (s)")
    b.set_ylabel("grip aperture (cm)")
    b.set_title("grip aperture")
    b.legend(fontsize=8)
    fig.suptitle(rec.clip)
    return fig


def condition_figure(profiles: pd.DataFrame, model: str) -> Figure:
    """Mean ± SD confidence profile per condition (thesis Fig. 5.8c).

    Parameters
    ----------
    profiles : pandas.DataFrame
        From :func:`condition_profiles`.
    model : str
        The model profiled (for the title).
    """
    fig, ax = new_figure(1, 1, size=(6.5, 4.5))
    a = ax[0, 0]
    for cond, g in profiles.groupby("condition", sort=False):
        line, = a.plot(g["phase"] * 100, g["mean"] * 100, lw=1.8,
                       label=f"{cond} (n={int(g['n'].iloc[0])})")
        a.fill_between(g["phase"] * 100, (g["mean"] - g["sd"]) * 100,
                       (g["mean"] + g["sd"]) * 100, color=line.get_color(), alpha=0.2)
    a.set_xlabel("movement time (%)")
    a.set_ylabel("confidence C (cm, weighted)")
    a.set_title(f"mean ± SD confidence of {model}")
    a.axhline(0, color="0.7", lw=0.6)
    a.legend(fontsize=8)
    return fig
