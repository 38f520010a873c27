"""One clip's report: ``<clip>.recognition.json``, the per-step CSV and two figures.

:class:`ClipSummary` is what a batch keeps of a scored clip: built from the
:class:`~perception.recognition.result.Recognition` in memory for a clip
scored now, or from its JSON for a clip a rerun reuses.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from perception.io.atomic import save_figure, write_csv, write_json
from perception.recognition.result import Recognition

__all__ = ["ClipSummary", "clip_outputs", "write_clip_report"]


@dataclass(frozen=True, eq=False)
class ClipSummary:
    """What a batch keeps of one scored clip (rebuilt from its JSON on resume).

    Attributes
    ----------
    clip : str
        Clip name.
    time : (N,) array
        Time since onset, s.
    names, kinds : list of str
        Models and their kinds.
    confidence : (M, N) array
        Thesis-rule confidence.
    final_log_likelihood : (M,) array
        Likelihood-rule score at the end.
    winner : str
        The winning model.
    rule : str
        Rule that picked the winner.
    tracking : dict, optional
        The clip's tracking quality (the JSON's ``tracking`` key).
    """

    clip: str
    time: np.ndarray
    names: list[str]
    kinds: list[str]
    confidence: np.ndarray
    final_log_likelihood: np.ndarray
    winner: str
    rule: str
    tracking: dict | None = None

    @classmethod
    def from_dict(cls, d: dict) -> ClipSummary:
        """From the content of a ``<clip>.recognition.json``.

        Parameters
        ----------
        d : dict
            The parsed JSON.
        """
        names = [m["name"] for m in d["models"]]
        return cls(
            clip=d["clip"],
            time=np.asarray(d["time"], dtype=float),
            names=names,
            kinds=[m["kind"] for m in d["models"]],
            confidence=np.array([d["confidence"][n] for n in names], dtype=float),
            final_log_likelihood=np.array([m.get("final_log_likelihood", np.nan)
                                           for m in d["models"]], dtype=float),
            winner=d["winner"],
            rule=d["rule"],
            tracking=d.get("tracking"),
        )

    @classmethod
    def from_recognition(cls, rec: Recognition) -> ClipSummary:
        """From a :class:`~perception.recognition.engine.Recognition`.

        Parameters
        ----------
        rec : Recognition
            A scored clip.
        """
        return cls(clip=rec.clip, time=rec.time, names=list(rec.names), kinds=list(rec.kinds),
                   confidence=rec.confidence, final_log_likelihood=rec.log_likelihood[:, -1],
                   winner=rec.winner, rule=rec.rule)


def clip_outputs(out: Path, clip: str) -> dict[str, Path]:
    """Paths of the files :func:`write_clip_report` writes for ``clip`` in ``out``.

    Parameters
    ----------
    out : Path
        Report folder.
    clip : str
        Clip name.
    """
    return {
        "json": out / f"{clip}.recognition.json",
        "csv": out / f"{clip}.confidence.csv",
        "confidence_png": out / f"{clip}.confidence.png",
        "paths_png": out / f"{clip}.paths.png",
    }


def write_clip_report(rec: Recognition, out: Path, *, extra: dict | None = None,
                      figures: bool = True) -> dict[str, Path]:
    """Write ``<clip>.recognition.json``, the per-step CSV and the two figures.

    Parameters
    ----------
    rec : Recognition
        A scored clip.
    out : Path
        Report folder (created if missing).
    extra : dict, optional
        More keys for the JSON (e.g. the batch's input fingerprint).
    figures : bool
        Draw the figures (matplotlib is imported only then); without them,
        figures of an earlier run are removed, since they would show another
        result.

    Returns
    -------
    dict of Path
        The files written (see :func:`clip_outputs`).
    """
    paths = clip_outputs(Path(out), rec.clip)
    if figures:
        from perception.report.figures import confidence_figure, paths_figure

        save_figure(paths["confidence_png"], confidence_figure(rec))
        save_figure(paths["paths_png"], paths_figure(rec))
    else:
        paths["confidence_png"].unlink(missing_ok=True)
        paths["paths_png"].unlink(missing_ok=True)
    write_csv(paths["csv"], rec.to_pandas())
    # the JSON last: its presence marks the clip's report complete
    write_json(paths["json"], {**rec.to_dict(), **(extra or {})})
    return paths
