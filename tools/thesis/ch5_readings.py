"""Chapter 5's confidence rule (eqs. 5.1, 5.6-5.8) under every reading the thesis allows.

The thesis prints ``dC_r = sgn(r_n - r_n-1) sgn(r^pred_n - r^pred_n-1) (r^pred_n - r^pred_n-1) w_r``
(and likewise ``dC_g``) and describes it in words (line 1070). Three things are
open, and each gives a reading scored here from the same predictions
(:class:`~perception.recognition.result.Recognition`, one recognition per clip):

``text`` (ours, the verdict's)
    +1 when the observed and predicted changes agree, -1 when not, times the
    predicted change's magnitude: the bullets of line 1070. The predicted
    change is the prediction less the last observed value.
``printed``
    The equation as printed: ``sgn(obs) sgn(pred) pred = sgn(obs) |pred|``, the
    prediction's own direction drops out; the change in distance signed as line
    1070 defines it (positive when the hand moves closer), so this is a hybrid
    of the print and the text.
``literal``
    The print to the letter: ``sgn(r_n - r_n-1) |pred|``, an approaching hand
    (r falling) lowering every model's confidence.
``consecutive``
    The text's sign, with ``r^pred_n-1`` read as the model's previous prediction
    (line 1072: "the same value for a given inverse model"): the predicted change
    is between consecutive predictions, not from the last observation.

:data:`ALLOWED` says which of them the thesis's text and figures allow; a claim
counts as reproduced only if it holds under all of those.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import find_peaks

#: The readings, in the order numbers.md lists them.
READINGS = ("text", "printed", "literal", "consecutive")
#: What each reading is, for numbers.md.
MEANING = {
    "text": "sign agreement x |predicted change| (line 1070's words; ours)",
    "printed": "sgn(observed change, positive closer) x |predicted change| (the print, "
               "with line 1070's sign of dr)",
    "literal": "sgn(r_n - r_n-1) x |predicted change| (the print to the letter)",
    "consecutive": "the text's sign, predicted change between consecutive predictions "
                   "(line 1072's notation)",
}
#: Readings the thesis's text and figures allow, and why the others are not.
ALLOWED = ("text", "printed", "consecutive")
EXCLUDED = {
    "literal": "line 1070 defines r_n - r_n-1 as positive when the hand moves closer, the "
               "opposite of its arithmetic; read to the letter, every approaching hand lowers "
               "every model's confidence, and Fig. 5.8 shows confidences that rise",
}


def _sgn(x: np.ndarray) -> np.ndarray:
    return np.where(x >= 0, 1.0, -1.0)


def reading_terms(rec, reading: str, w_r: float, w_g: float) -> tuple[np.ndarray, ...]:
    """Per-step transport and grip terms (M, N) of every model under ``reading``, and
    each model's path (M, N): ``w_r |dr_pred| + w_g |dg_pred|`` (the most it can earn).

    Parameters
    ----------
    rec : Recognition
        One clip's recognition (its predictions, observation and scored steps).
    reading : str
        One of :data:`READINGS`.
    w_r, w_g : float
        Weights of the two terms.
    """
    if reading not in READINGS:
        raise ValueError(f"reading: expected one of {READINGS}, got {reading!r}")
    obs = rec.scored_movement  # what the predictions are of
    r_obs, g_obs = obs.r, obs.g
    r_pred, g_pred = rec.predicted_r, rec.predicted_g
    grasp = np.array([k == "grasp" for k in rec.kinds])[:, None]
    valid = np.asarray(rec.scored, dtype=bool)

    def previous(a):
        return np.concatenate([np.full_like(a[..., :1], np.nan), a[..., :-1]], axis=-1)

    dr_obs, dg_obs = r_obs - previous(r_obs), g_obs - previous(g_obs)
    if reading == "consecutive":
        dr_pred, dg_pred = r_pred - previous(r_pred), g_pred - previous(g_pred)
        valid = valid & previous(valid.astype(float)).astype(bool)
    else:
        dr_pred, dg_pred = r_pred - previous(r_obs), g_pred - previous(g_obs)
    if reading in ("text", "consecutive"):
        dC_r = _sgn(dr_obs) * _sgn(dr_pred) * np.abs(dr_pred) * w_r
        dC_g = _sgn(dg_obs) * _sgn(dg_pred) * np.abs(dg_pred) * w_g
    else:
        sign_r = _sgn(-dr_obs) if reading == "printed" else _sgn(dr_obs)
        dC_r = sign_r * np.abs(dr_pred) * w_r
        dC_g = _sgn(dg_obs) * np.abs(dg_pred) * w_g
    dC_g = dC_g * grasp
    path = np.abs(dr_pred) * w_r + np.abs(dg_pred) * w_g * grasp
    ok = valid & np.isfinite(dr_pred) & np.isfinite(dg_pred)
    return tuple(np.where(ok, x, 0.0) for x in (dC_r, dC_g, path))


def reading_clip(rec, reading: str, w_r: float, w_g: float) -> dict:
    """One clip's recognition report under ``reading``, in the keys the claims read
    (``<clip>.recognition.json``'s): clip, models, time, confidence, transport_confidence,
    aperture; ``path``, each model's summed :func:`reading_terms` path, and
    ``durations``, each model's movement time, s."""
    dC_r, dC_g, path = reading_terms(rec, reading, w_r, w_g)
    conf, transport = np.cumsum(dC_r + dC_g, axis=1), np.cumsum(dC_r, axis=1)
    return {
        "clip": rec.clip,
        "models": [{"name": n, "kind": k, "final_confidence": float(c[-1])}
                   for n, k, c in zip(rec.names, rec.kinds, conf)],
        "time": [float(t) for t in rec.time],
        "confidence": dict(zip(rec.names, conf.tolist())),
        "transport_confidence": dict(zip(rec.names, transport.tolist())),
        "aperture": [None if not np.isfinite(g) else float(g) for g in rec.scored_movement.g],
        "path": dict(zip(rec.names, path.sum(axis=1).tolist())),
        "durations": {m.name: float(m.spec.task.get("duration", np.nan)) for m in rec.models},
    }


def balanced_ratio(recs: list, model: str, reading: str = "text") -> float:
    """w_r / w_g that gives the transport and grip terms the same summed |dC| on ``recs``
    (normal clips, ``model`` the reference): line 1125's aim, measured instead of ½.

    The median over clips of ``sum |dC_g| / sum |dC_r|`` at unit weights.
    """
    ratios = []
    for rec in recs:
        i = rec.names.index(model)
        dC_r, dC_g, _ = reading_terms(rec, reading, 1.0, 1.0)
        ratios.append(np.abs(dC_g[i]).sum() / np.abs(dC_r[i]).sum())
    return float(np.median(ratios))


def oco_landmarks(phase: np.ndarray, g: np.ndarray) -> tuple[float, float, float] | None:
    """(first peak, deepest unexpected closing, re-opening peak) of an open-close-open
    aperture, as phases; None without an interior minimum.

    The closing is the aperture's most prominent interior minimum (at least 5 mm);
    the peaks are the largest apertures before and after it.
    """
    g = np.asarray(g, dtype=float)
    ok = np.isfinite(g)
    if ok.sum() < 3:
        return None
    g = np.interp(phase, phase[ok], g[ok])
    dips, props = find_peaks(-g, prominence=0.005)
    if not len(dips):
        return None
    k = int(dips[np.argmax(props["prominences"])])
    return (float(phase[np.argmax(g[:k])]), float(phase[k]),
            float(phase[k + np.argmax(g[k:])]))


def survived(verdicts: dict[str, str]) -> tuple[str, str]:
    """The verdict over the readings, and the words saying which it survives.

    ``agree`` when it agrees under every allowed reading, ``differs`` when under
    none, ``conditional`` otherwise (it flips with a choice the thesis leaves open).

    Parameters
    ----------
    verdicts : dict
        Reading -> verdict (``agree`` or not) under it.
    """
    holds = [r for r in READINGS if verdicts.get(r) == "agree"]
    fails = [r for r in READINGS if r in verdicts and r not in holds]
    allowed = [r for r in ALLOWED if r in verdicts]
    if all(r in holds for r in allowed):
        verdict = "agree"
    elif not any(r in holds for r in allowed):
        verdict = "differs"
    else:
        verdict = "conditional"
    words = (f"survives {', '.join(holds) or 'no reading'}"
             + (f"; not {', '.join(fails)}" if fails else ""))
    return verdict, words
