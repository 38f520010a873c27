"""The result of scoring one demonstration against a repertoire."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

if TYPE_CHECKING:
    from perception.observation import Observation

__all__ = ["Recognition"]


@dataclass(frozen=True, eq=False)
class Recognition:
    """Confidence of every model over one demonstration.

    Attributes
    ----------
    clip : str
        Clip name.
    time : (N,) array
        Time since movement onset, s.
    frame : (N,) int array
        Video frame of each sample.
    names, kinds : list of str
        Model names and kinds (M of them).
    confidence : (M, N) array
        Thesis-rule confidence C_n (C_0 = 0).
    dC_r, dC_g : (M, N) arrays
        Per-step transport and grip terms of the thesis rule.
    log_likelihood : (M, N) array
        Cumulative log-likelihood of the observed (r, g).
    predicted : dict of (M, N, 2) arrays
        Predicted ``wrist``, ``finger``, ``thumb`` positions, m (NaN at n = 0).
    observation : Observation
        What was scored.
    rule : str
        The rule that picks the winner.
    """

    clip: str
    time: np.ndarray
    frame: np.ndarray
    names: list[str]
    kinds: list[str]
    confidence: np.ndarray = field(repr=False)
    dC_r: np.ndarray = field(repr=False)
    dC_g: np.ndarray = field(repr=False)
    log_likelihood: np.ndarray = field(repr=False)
    predicted: dict = field(repr=False)
    observation: Observation = field(repr=False)
    rule: str = "likelihood"

    def score(self, rule: str | None = None) -> np.ndarray:
        """(M, N) cumulative score under ``rule`` (default: the winner's rule)."""
        rule = rule or self.rule
        return self.log_likelihood if rule == "likelihood" else self.confidence

    def winner_at(self, n: int, rule: str | None = None) -> str:
        """Name of the best model after sample ``n`` (index into :attr:`time`) under ``rule``."""
        return self.names[int(np.argmax(self.score(rule)[:, n]))]

    @property
    def winner(self) -> str:
        """Best model at the end of the demonstration, by :attr:`rule`."""
        return self.winner_at(-1)

    @property
    def final_confidence(self) -> dict[str, float]:
        """Thesis-rule confidence of each model at the end."""
        return {n: float(c) for n, c in zip(self.names, self.confidence[:, -1])}

    @property
    def predicted_r(self) -> np.ndarray:
        """(M, N) predicted distance of the grip midpoint to the object, m."""
        mid = 0.5 * (self.predicted["finger"] + self.predicted["thumb"])
        return np.linalg.norm(mid, axis=-1)

    @property
    def predicted_g(self) -> np.ndarray:
        """(M, N) predicted grip aperture, m."""
        return np.linalg.norm(self.predicted["finger"] - self.predicted["thumb"], axis=-1)

    def to_pandas(self) -> pd.DataFrame:
        """Per-step terms, one row per model and sample.

        Columns: time, frame, model, kind, C, dC_r, dC_g, log_likelihood.
        """
        M, N = self.confidence.shape
        return pd.DataFrame({
            "time": np.tile(self.time, M),
            "frame": np.tile(self.frame, M),
            "model": np.repeat(self.names, N),
            "kind": np.repeat(self.kinds, N),
            "C": self.confidence.ravel(),
            "dC_r": self.dC_r.ravel(),
            "dC_g": self.dC_g.ravel(),
            "log_likelihood": self.log_likelihood.ravel(),
        })

    def to_dict(self) -> dict:
        """The recognition report (``<clip>.recognition.json``)."""
        return {
            "clip": self.clip,
            "models": [
                {"name": n, "kind": k, "final_confidence": float(c),
                 "final_log_likelihood": float(ll)}
                for n, k, c, ll in zip(self.names, self.kinds, self.confidence[:, -1],
                                       self.log_likelihood[:, -1])
            ],
            "winner": self.winner,
            "rule": self.rule,
            "time": [float(t) for t in self.time],
            "confidence": {n: [float(c) for c in row]
                           for n, row in zip(self.names, self.confidence)},
        }
