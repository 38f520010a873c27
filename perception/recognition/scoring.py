"""The two confidence rules that score each model's one-step predictions.

``thesis`` (eqs. 5.6-5.8)
    ``dC_r = sgn(dr_obs) sgn(dr_pred) |dr_pred| w_r``, likewise ``dC_g`` with
    ``w_g``; ``sgn(0) = +1``; ``w_r / w_g = 1/2``. The thesis prints the last
    factor without the absolute value; its text (agreeing motion raises
    confidence, faster agreement raises it faster) needs the magnitude. That
    reading (``sign="text"``, the default) is ours; ``sign="printed"`` scores
    the equations as printed, which reduce to ``sgn(dr_obs) |dr_pred| w_r``:
    the observed direction alone decides the sign, with the change in distance
    positive when the hand moves closer, as the thesis defines it (see
    :data:`THESIS_SIGNS`).
    Reach-only models use ``dC_r`` alone. It rewards agreeing directions, so
    it yields the chapter 5 confidence profiles, but it cannot prefer a model
    that predicts no grip motion over one that does.
``likelihood``
    The log-likelihood of each observed ``(r, g)`` under the model's own
    predictive distribution: the plan's estimation-error covariance mapped
    through the chains' Jacobians, plus a fixed tracking noise
    (``HammerParams.obs_sd``, 1 mm). Every model is
    scored on the same quantities, so it can tell kinds and speeds apart.

With ``r`` the distance from the grip midpoint to the object centre and
``g`` the grip aperture (thesis eqs. 5.3-5.5). See docs/recognition.md.
"""

from __future__ import annotations

import numpy as np

from perception.rowwise import last_norm

__all__ = ["RULES", "THESIS_SIGNS", "thesis_rule", "likelihood_rule"]

#: Rules that can pick the winner.
RULES = ("likelihood", "thesis")
#: Readings of the sign in the thesis rule (eqs. 5.1, 5.7, 5.8): ``text``, as the
#: thesis's words say (+1 when observed and predicted changes agree, -1 when they
#: differ, times the predicted change's magnitude); ``printed``, the equations as
#: printed, ``sgn(observed) sgn(predicted) (predicted change)``, which is
#: ``sgn(observed) |predicted change|`` (the change in distance positive when the
#: hand moves closer, as the thesis defines it; the aperture's when it opens).
THESIS_SIGNS = ("text", "printed")


def _sgn(x: np.ndarray) -> np.ndarray:
    return np.where(x >= 0, 1.0, -1.0)


def thesis_rule(r_obs: np.ndarray, g_obs: np.ndarray, r_pred: np.ndarray, g_pred: np.ndarray,
                grasp: np.ndarray, valid: np.ndarray, w_r: float,
                w_g: float, sign: str = "text") -> tuple[np.ndarray, np.ndarray]:
    """Per-step transport and grip terms of the thesis rule (eqs. 5.6-5.7).

    Parameters
    ----------
    r_obs, g_obs : (N,) arrays
        Observed r and g, m.
    r_pred, g_pred : (M, N) arrays
        Each model's one-step prediction of r and g, m (NaN at n = 0).
    grasp : (M,) bool array
        Which models have a grip channel (reach-only models score ``dC_r`` alone).
    valid : (M, N) bool array
        Steps that count; others score 0.
    w_r, w_g : float
        Weights of the transport and grip terms.
    sign : str
        ``"text"`` (default) or ``"printed"``: the reading of eqs. 5.1/5.7/5.8
        (:data:`THESIS_SIGNS`).

    Returns
    -------
    dC_r, dC_g : (M, N) arrays
        The terms; the confidence is ``cumsum(dC_r + dC_g)`` (eq. 5.8).
    """
    dr_obs = np.diff(r_obs, prepend=np.nan)
    dg_obs = np.diff(g_obs, prepend=np.nan)
    dr_pred = r_pred - np.concatenate([[np.nan], r_obs[:-1]])
    dg_pred = g_pred - np.concatenate([[np.nan], g_obs[:-1]])
    if sign not in THESIS_SIGNS:
        raise ValueError(f"sign: expected one of {THESIS_SIGNS}, got {sign!r}")
    if sign == "text":
        dC_r = _sgn(dr_obs) * _sgn(dr_pred) * np.abs(dr_pred) * w_r
        dC_g = _sgn(dg_obs) * _sgn(dg_pred) * np.abs(dg_pred) * w_g * grasp[:, None]
    else:
        # printed: sgn(obs) sgn(pred) pred = sgn(obs) |pred|, the prediction's direction
        # drops out; the change in distance is signed as the thesis defines it, positive
        # when the hand moves closer (line 1070), the aperture's positive when it opens
        dC_r = _sgn(-dr_obs) * np.abs(dr_pred) * w_r
        dC_g = _sgn(dg_obs) * np.abs(dg_pred) * w_g * grasp[:, None]
    # sgn(NaN) is +1, not NaN: what counts must come from the inputs.
    ok = valid & np.isfinite(dr_pred) & np.isfinite(dg_pred)
    return np.where(ok, dC_r, 0.0), np.where(ok, dC_g, 0.0)


def _unit(v: np.ndarray, norm: np.ndarray | None = None) -> np.ndarray:
    """``v`` (..., 2) over its ``norm`` (...), where the caller has it; (1, 0) where ~0."""
    norm = last_norm(v)[..., None] if norm is None else norm[..., None]
    return np.where(norm > 1e-9, v / np.where(norm > 1e-9, norm, 1), np.array([1.0, 0.0]))


def likelihood_rule(r_obs: np.ndarray, g_obs: np.ndarray, midpoint: np.ndarray,
                    opening: np.ndarray, cov_tips: np.ndarray, valid: np.ndarray,
                    obs_sd: float, norms: tuple[np.ndarray, np.ndarray] | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Per-step log-likelihood of the observed ``(r, g)`` under each model's prediction.

    The predicted wrist, finger and thumb positions have Cartesian covariances
    ``cov_tips``; r and g are linearised about the prediction (along the unit
    vectors of the predicted midpoint and opening), and the tracked positions
    add ``obs_sd`` of independent noise per coordinate.

    Parameters
    ----------
    r_obs, g_obs : (N,) arrays
        Observed r and g, m.
    midpoint, opening : (M, N, 2) arrays
        Predicted grip midpoint (finger + thumb) / 2 and opening finger - thumb, m.
    cov_tips : (M, N, 3, 2, 2) array
        Predicted covariance of the wrist, finger and thumb positions, m^2.
    valid : (M, N) bool array
        Steps that count; others score 0.
    obs_sd : float
        SD of a tracked position after filtering, m.
    norms : ((M, N), (M, N)) arrays, optional
        The predicted r and g (the norms of ``midpoint`` and ``opening``), where the
        caller has them.

    Returns
    -------
    log_likelihood : (M, N) array
        Log-likelihood of each step (0 where not valid).
    mahalanobis : (M, N) array
        The squared Mahalanobis distance of each step's observation from the
        prediction: the log-likelihood without its normalising term,
        ``-2 (log_likelihood + log 2 pi) - log det``; about 2 on average when
        the model's predictive distribution is right (0 where not valid).
    """
    Sw, Sf, St = cov_tips[:, :, 0], cov_tips[:, :, 1], cov_tips[:, :, 2]
    eye = np.eye(2)
    var = obs_sd**2
    # The midpoint moves with the wrist and half of each digit; the opening
    # with both digits; their covariance comes from the digits alone.
    cov_m = Sw + 0.25 * (Sf + St) + 0.5 * var * eye
    cov_d = Sf + St + 2 * var * eye
    cov_md = 0.5 * (Sf - St)
    r_pred, g_pred = (last_norm(midpoint), last_norm(opening)) if norms is None else norms
    um, ud = _unit(midpoint, r_pred), _unit(opening, g_pred)
    var_r = np.einsum("mni,mnij,mnj->mn", um, cov_m, um)
    var_g = np.einsum("mni,mnij,mnj->mn", ud, cov_d, ud)
    cov_rg = np.einsum("mni,mnij,mnj->mn", um, cov_md, ud)
    det = var_r * var_g - cov_rg**2
    er = r_obs[None] - r_pred
    eg = g_obs[None] - g_pred
    maha = (var_g * er**2 - 2 * cov_rg * er * eg + var_r * eg**2) / det
    dll = -0.5 * (np.log(det) + maha) - np.log(2 * np.pi)
    ok = valid & np.isfinite(dll)
    return np.where(ok, dll, 0.0), np.where(ok, maha, 0.0)
