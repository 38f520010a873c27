"""The observation passes of a stream resume from the rows before (issue 45, item 6, second
round), bitwise as a pass over every row.

The online recogniser recognises the rows so far after every row; each
pass below finds, in what it kept from the pass before, the part a row more
cannot change, and works on the rest:

* the scene (:func:`perception.observation.rest_scene`) is extended with
  the new rows, not fixed again;
* the onset (:func:`perception.movement_bounds.onset_time`) is found once the
  rows that decide it are seen; the end (``end_row``) is scanned from the
  last row scanned;
* the landmarks' spike test (:func:`perception.cleaning.spikes`) tests again
  only the samples within three windows of the last path's end;
* scoring a frame groups the leaves and builds their chains once per set.

Each is proved on every prefix of several streams: resumed == fresh, bit
for bit; the count tests fail before this change.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from _demos import default_repertoire

import perception.cleaning as cleaning
import perception.filtering as filtering
import perception.movement_bounds as movement_bounds
import perception.observation as observation
import perception.recognition.engine as engine
import perception.recognition.evidence as evidence
import perception.recognition.leaves as leaves
from perception.errors import InputError
from perception.landmarks import _LOWPASSED
from perception.observation import ObserveParams
from perception.online import OnlineRecognizer
from perception.pipeline import recognize_tracks
from perception.synthetic.demos import demo_tracks
from perception.synthetic.independent import draw_independent, independent_tracks

#: what the passes keep between calls, per thread
KEPT = (observation._SCENES.local, movement_bounds._ONSET.local, movement_bounds._END.local,
        cleaning._SPIKES.local, engine._SCORED.local, engine._RESUMABLE.local,
        filtering._KEPT.local, evidence._ARRIVAL.local, _LOWPASSED.local)


def _forget():
    """Nothing kept: the next pass is a pass over every row."""
    for kept in KEPT:
        kept.__dict__.clear()


def _fresh(call):
    """``call()`` with nothing kept from before, leaving what was kept as it was."""
    saved = [dict(k.__dict__) for k in KEPT]
    _forget()
    try:
        return call()
    finally:
        for k, s in zip(KEPT, saved):
            k.__dict__.clear()
            k.__dict__.update(s)


def _at_rest(tracks, seconds, seed=1, spikes=4, lost=6):
    """``tracks`` and then the hand at rest on the object for ``seconds`` more, with a few
    one-frame spikes (30 px) and lost markers there."""
    rng = np.random.default_rng(seed)
    extra = int(round(seconds / (tracks.time[1] - tracks.time[0])))
    tail = tracks.position[-1:] + rng.normal(0, 0.3, (extra,) + tracks.position.shape[1:])
    for j in rng.choice(extra, spikes, replace=False):
        tail[j, rng.integers(0, 3)] += rng.normal(0, 30, 2)
    for j in rng.choice(extra, lost, replace=False):
        tail[j, rng.integers(0, 3)] = np.nan
    pos = np.concatenate([tracks.position, tail])
    n = len(pos)
    seen = np.isfinite(pos).all(axis=2)
    return tracks.replace(frame=np.arange(n),
                          time=tracks.time[0] + (tracks.time[1] - tracks.time[0]) * np.arange(n),
                          position=pos, likelihood=seen.astype(np.float32),
                          status=np.where(seen, 1, 0).astype(tracks.status.dtype))


def _drawn(condition, duration, seed):
    return independent_tracks(draw_independent(condition, np.random.default_rng(seed),
                                               duration=duration), seed)[0]


#: streams: a movement then rest with spikes and losses, 30 and 60 frames/s, a digit lost
#: in the movement, a short and a long movement
STREAMS = {
    "normal-rest": lambda: _at_rest(_drawn("normal", 1.0, 5), 3.0),
    "delayed-rest-60": lambda: _at_rest(demo_tracks("delayed", 1, fps=60.0)[0], 1.5, seed=2),
    "normal-lost": lambda: demo_tracks("normal", 1, lost={"finger": slice(40, 46)})[0],
    "delayed-0.35s": lambda: _drawn("delayed", 0.35, 4),
    "normal-1.6s": lambda: _drawn("normal", 1.6, 4),
}


@pytest.fixture(scope="module")
def rep():
    return default_repertoire()


def _prefix(tracks, n):
    return tracks.replace(**{k: getattr(tracks, k)[:n]
                             for k in ("frame", "time", "position", "likelihood", "status")})


def _same(a, b, what):
    assert type(a) is type(b), what
    if isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape, what
        assert np.array_equal(a, b, equal_nan=True), what
        assert np.array_equal(np.signbit(a), np.signbit(b)) if a.dtype.kind == "f" else True
    elif isinstance(a, tuple | list):
        assert len(a) == len(b), what
        for k, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{what}[{k}]")
    elif dataclasses.is_dataclass(a):
        _same(dataclasses.astuple(a), dataclasses.astuple(b), what)
    elif isinstance(a, float) and np.isnan(a):
        assert np.isnan(b), what
    else:
        assert a == b, what


@pytest.mark.parametrize("name", STREAMS)
def test_every_frame_of_a_stream_is_a_fresh_pass_over_its_rows_bit_for_bit(rep, name):
    """After every row, the recognition resumed from the row before is the one a pass with
    nothing kept gives (every array and the report, bitwise)."""
    tracks = STREAMS[name]()
    _forget()
    rec = OnlineRecognizer(rep, markers=tracks.markers, tracker_attrs=dict(tracks.tracker))
    judged = 0
    for n in range(1, tracks.n_frames + 1):
        rec.update(tracks.position[n - 1], tracks.time[n - 1],
                   likelihood=tracks.likelihood[n - 1], status=tracks.status[n - 1])
        if rec.prefix is None:
            continue
        fresh = _fresh(lambda: recognize_tracks(rec.tracks(), rep, rec.settings, clip="stream"))
        judged += 1
        assert json.dumps(rec.prefix.to_dict()) == json.dumps(fresh.to_dict()), n
        for field in ("confidence", "log_likelihood", "dC_r", "dC_g", "mahalanobis"):
            _same(getattr(rec.prefix, field), getattr(fresh, field), f"{field} at row {n}")
        _same(rec.prefix.evidence.familiarity, fresh.evidence.familiarity, f"familiarity {n}")
        assert repr(rec.prefix.evidence) == repr(fresh.evidence), n
    assert judged >= 12


@pytest.mark.parametrize("name", ["normal-rest", "delayed-rest-60"])
def test_every_prefix_scene_onset_and_end_are_the_fresh_ones(name):
    """rest_scene, onset_time and the end scan, resumed from the prefix a row shorter, are a
    pass over the prefix with nothing kept."""
    tracks = STREAMS[name]()
    params = ObserveParams()
    _forget()
    for n in range(2 * params.rest_frames, tracks.n_frames + 1):
        rows = _prefix(tracks, n)

        def passes(rows=rows):
            try:
                sc = observation.rest_scene(rows, params)
                p = observation._prepare(rows, params, "stream")
            except InputError as exc:
                return exc.problem
            return (*sc, p.filtered, p.span)

        _same(passes(), _fresh(passes), f"row {n}")


def test_the_spike_test_of_every_prefix_is_the_fresh_one():
    """Paths with spikes, lost samples and steps of 30 and 120 frames/s: each prefix's
    flags, resumed from the prefix before, are the whole path's."""
    rng = np.random.default_rng(3)
    for fps, n in ((30.0, 240), (120.0, 400)):
        time = np.arange(n) / fps
        path = np.cumsum(rng.normal(0, 0.002, (n, 2)), axis=0)
        spiked = rng.choice(n, n // 10, replace=False)
        path[spiked] += rng.normal(0, 0.03, (len(spiked), 2))
        path[rng.choice(n, n // 12, replace=False)] = np.nan
        cleaning._SPIKES.local.__dict__.clear()
        found = 0
        for m in range(1, n + 1):
            resumed = cleaning.spikes(time[:m], path[:m])
            fresh = _fresh(lambda m=m, t=time, p=path: cleaning.spikes(t[:m], p[:m]))
            assert np.array_equal(resumed, fresh), (fps, m)
            found = max(found, int(resumed.sum()))
        assert found >= n // 20  # the paths have spikes to find


def test_a_path_a_sample_longer_is_tested_near_its_end_only(monkeypatch):
    calls = []
    median = cleaning.median_filter

    def counted(x, *args, **kw):
        calls.append(len(x))
        return median(x, *args, **kw)

    monkeypatch.setattr(cleaning, "median_filter", counted)
    time = np.arange(300) / 30.0
    path = np.cumsum(np.random.default_rng(1).normal(0, 0.002, (300, 2)), axis=0)
    cleaning._SPIKES.local.__dict__.clear()
    cleaning.spikes(time[:299], path[:299])
    assert calls == [299]
    cleaning.spikes(time, path)
    half = 2  # 0.05 s at 30 frames/s
    assert calls[1] <= 4 * half + 2  # the last three windows and one more, not 300 samples


def test_a_stream_fixes_its_scene_and_finds_its_onset_once(rep, monkeypatch):
    """Row after row, the scene is fixed at the first recognition and extended after; the
    onset is found again only until the wrist has passed the onset profile's displacements
    (their crossings fit its time scale), then kept."""
    fixed, onsets = [], []
    transform, latency = observation._scene_transform, ObserveParams.onset_latency

    def counted_fix(*args):
        fixed.append(1)
        return transform(*args)

    def counted_onset(self, displacement):
        onsets.append(displacement)  # each pass starts again from the threshold's
        return latency(self, displacement)

    monkeypatch.setattr(observation, "_scene_transform", counted_fix)
    monkeypatch.setattr(ObserveParams, "onset_latency", counted_onset)
    tracks = STREAMS["normal-rest"]()
    _forget()
    rec = OnlineRecognizer(rep, markers=tracks.markers, tracker_attrs=dict(tracks.tracker))
    for i in range(tracks.n_frames):
        rec.update(tracks.position[i], tracks.time[i])
    assert rec.prefix is not None
    assert len(fixed) == 1
    passes = 1 + sum(b <= a for a, b in zip(onsets, onsets[1:]))
    # from the threshold's hold to the last displacement's, not at every row of the stream
    assert 1 <= passes <= 10 < tracks.n_frames // 4, passes


def test_scoring_a_frame_builds_no_chain(rep, monkeypatch):
    """The leaves' groups and their chains are found once per set of leaves, not per frame."""
    tracks = _drawn("normal", 1.0, 5)
    obs = recognize_tracks(tracks, rep).scored_observation
    models = recognize_tracks(tracks, rep).models
    scorer = engine.StepScorer(models, steps=80)
    scorer.step(obs.time[0], obs.wrist[0], obs.finger[0], obs.thumb[0])
    built = []
    chain = engine.TwoLinkChain

    def counted(*args, **kw):
        built.append(1)
        return chain(*args, **kw)

    monkeypatch.setattr(engine, "TwoLinkChain", counted)
    monkeypatch.setattr(leaves, "TwoLinkChain", counted)
    for n in range(1, 5):
        scorer.step(obs.time[n], obs.wrist[n], obs.finger[n], obs.thumb[n])
    assert not built
    # and the frames scored one at a time are the engine's, bitwise
    one = engine.StepScorer(models, steps=80)
    one.score(obs.time[:5], obs.wrist[:5], obs.finger[:5], obs.thumb[:5])
    assert np.array_equal(one.log_likelihood, scorer.log_likelihood)


def test_rows_changed_before_the_end_are_not_resumed():
    """A prefix whose earlier rows differ (the object moved in place) is fixed afresh."""
    tracks = STREAMS["normal-rest"]()
    params = ObserveParams()
    _forget()
    first = observation.rest_scene(_prefix(tracks, 40), params)
    moved = tracks.position.copy()
    moved[:, list(tracks.markers).index("object")] += 2.0
    longer = dataclasses.replace(_prefix(tracks, 41), position=moved[:41])
    second = observation.rest_scene(longer, params)
    assert not np.array_equal(first.transform.origin_px, second.transform.origin_px)
    _same(tuple(second), tuple(_fresh(lambda: observation.rest_scene(longer, params))), "scene")


def test_one_prefix_test_for_every_resumed_pass():
    from perception.resume import begins_with

    t = np.arange(6.0)
    xy = np.arange(12.0).reshape(6, 2)
    xy[2] = np.nan
    assert begins_with((t, xy), (t[:4], xy[:4].copy()))  # NaN equal to NaN
    assert begins_with((t, xy), (t, xy))
    assert not begins_with((t[:3], xy[:3]), (t[:4], xy[:4]))  # longer than the new series
    other = xy[:4].copy()
    other[1, 0] += 1e-12  # one bit off, not at the last row
    assert not begins_with((t, xy), (t[:4], other))
    assert not begins_with((t, xy), (t[:4], xy[:4, :1]))  # another shape
    assert begins_with((t, xy), (t[:0], xy[:0]))  # nothing kept: a prefix of anything
