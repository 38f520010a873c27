"""Reports: the clip summary and its JSON, the batch tables, statistics and the page."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from _demos import default_repertoire, demo_tracks
from PIL import Image

from perception import batch
from perception.batch import ClipResult, summary_table
from perception.pipeline import recognize_clip
from perception.report import ClipSummary, write_batch_report, write_clip_report
from perception.report.clip import clip_figures
from perception.report.conditions import (
    aperture_profiles,
    condition_statistics,
    reference_model,
    typical_clips,
)


@pytest.fixture(scope="module")
def scored(tmp_path_factory):
    out = tmp_path_factory.mktemp("clips")
    rep = default_repertoire()
    recs = {}
    for i, cond in enumerate(["normal", "normal", "delayed", "delayed", "reach"]):
        rec = recognize_clip(demo_tracks(cond, i)[0], rep, clip=f"{cond}-{i}")
        write_clip_report(rec, out, extra={"condition": cond, "tracking": {"lost": 0}})
        recs[rec.clip] = (rec, cond)
    return out, recs


def test_the_clip_json_reads_back_as_the_summary_made_in_memory(scored):
    out, recs = scored
    for name, (rec, cond) in recs.items():
        d = json.loads((out / f"{name}.recognition.json").read_text())
        a = ClipSummary.from_recognition(rec, {"condition": cond, "tracking": {"lost": 0}})
        b = ClipSummary.from_dict(d)
        assert (a.verdict, a.winner, a.reference_model) == (b.verdict, b.winner,
                                                            b.reference_model)
        assert a.familiarity == pytest.approx(b.familiarity)
        assert a.margin == pytest.approx(b.margin)
        np.testing.assert_allclose(a.confidence, b.confidence)
        np.testing.assert_allclose(a.transport, b.transport)
        np.testing.assert_allclose(a.aperture, b.aperture)
        assert b.extras == {"condition": cond, "tracking": {"lost": 0}}  # a later key fits in
        # the transport and grip terms add up to the confidence
        np.testing.assert_allclose(b.transport + b.grip, b.confidence)


def test_a_json_from_before_the_verdict_still_reads(scored):
    out, recs = scored
    d = json.loads((out / "normal-0.recognition.json").read_text())
    for key in ("verdict", "familiarity", "margin", "familiarity_threshold", "reference_model",
                "transport_confidence", "aperture"):
        del d[key]
    for m in d["models"]:
        del m["misfit"], m["familiarity"]
    s = ClipSummary.from_dict(d)
    assert s.verdict is None and np.isnan(s.familiarity) and np.isnan(s.margin)
    assert np.isnan(s.aperture).all() and s.aperture.shape == s.time.shape


def test_summary_columns_and_a_column_added_by_another_step(scored, monkeypatch):
    _, recs = scored
    results = [ClipResult(n, c, "ok", summary=ClipSummary.from_recognition(r))
               for n, (r, c) in recs.items()]
    results.append(ClipResult("bad", "normal", "failed", error="bad: not a video"))
    monkeypatch.setattr(batch, "CLIP_COLUMNS",
                        [*batch.CLIP_COLUMNS, ("lost_frames", lambda s: 3)])
    table = summary_table(results)
    assert list(table.columns[:10]) == ["clip", "condition", "winner", "rule", "verdict",
                                        "familiarity", "margin", "winner_log_likelihood",
                                        "lost_frames", "reference_model"]
    assert list(table.columns[-4:]) == ["status", "reused", "error", "reason"]
    ok = table[table["status"] == "ok"].set_index("clip")
    assert (ok["reference_model"] == "grasp-1.0s").all()  # the model of the normal clips
    for name, (rec, _) in recs.items():
        assert ok.loc[name, "verdict"] == rec.verdict
        assert ok.loc[name, "winner_log_likelihood"] == pytest.approx(
            rec.log_likelihood[rec.names.index(rec.winner), -1])
        assert ok.loc[name, "reference_confidence"] == pytest.approx(
            ok.loc[name, "conf_grasp-1.0s"])
    bad = table.set_index("clip").loc["bad"]
    assert pd.isna(bad["verdict"]) and np.isnan(bad["reference_confidence"])


def test_statistics_report_their_type_df_and_effect_size():
    summary = pd.DataFrame({
        "clip": list("abcdef"), "status": "ok",
        "condition": ["n", "n", "n", "d", "d", "d"],
        "conf_m": [3.0, 4.0, 5.0, 1.0, 2.0, 3.0]})
    stats = condition_statistics(summary, "m")
    anova, t = stats.iloc[0], stats.iloc[1]
    assert (anova["statistic_type"], anova["df"]) == ("F", "1, 4")
    # eta^2 = between / total = 6 / 10
    assert anova["effect_size_type"] == "eta^2" and anova["effect_size"] == pytest.approx(0.6)
    assert t["statistic_type"] == "t" and t["mean_difference"] == pytest.approx(2.0)
    # Hedges' g: 2 / pooled SD 1, times 1 - 3 / (4 * 6 - 9)
    assert t["effect_size_type"] == "Hedges' g"
    assert t["effect_size"] == pytest.approx(2.0 * (1 - 3 / 15))
    assert float(t["df"]) == pytest.approx(4.0)
    assert t["statistic"] ** 2 == pytest.approx(anova["statistic"])  # equal variances here
    assert (anova["n_per_group"], anova["note"]) == ("n=3, d=3", "")


def test_reference_model_typical_clips_and_aperture_profiles(scored):
    _, recs = scored
    sums = [ClipSummary.from_recognition(r) for r, _ in recs.values()]
    conds = [c for _, c in recs.values()]
    assert reference_model(sums, conds) == "grasp-1.0s"
    chosen, which = typical_clips(sums, conds, "grasp-1.0s")
    assert which == ["normal", "delayed", "reach"] and chosen[2].clip == "reach-4"
    ap = aperture_profiles(sums, conds).set_index("condition")
    # normal grasps open to about object + 2 cm; reaches stay closed
    assert 0.11 < ap.loc["normal", "mean"].max() < 0.135
    assert ap.loc["reach", "mean"].max() < 0.01


def test_figures_beside_a_clip_are_its_own_only(tmp_path):
    for name in ("a.confidence.png", "a.paths.png", "a.contact.png", "a.b.confidence.png",
                 "ab.contact.png", "a.notes.txt"):
        (tmp_path / name).write_bytes(b"x")
    assert [p.name for p in clip_figures(tmp_path, "a")] == ["a.confidence.png", "a.paths.png",
                                                              "a.contact.png"]


#: The batch report's figures and their sizes (pixels; 120 dpi).
FIGURES = {"aperture_profiles.png": (900, 600), "confidence_single.png": (900, 600),
           "confidence_all.png": (900, 600), "condition_profiles.png": (1872, 576)}


def test_the_batch_page_and_its_figures(scored):
    out, recs = scored
    results = [ClipResult(n, c, "ok", summary=ClipSummary.from_recognition(r))
               for n, (r, c) in recs.items()]
    summary = summary_table(results)
    write_batch_report(summary, {r.clip: r.summary for r in results}, out,
                       models=default_repertoire().models)
    for name, size in FIGURES.items():
        with Image.open(out / name) as png:
            assert (png.format, png.size) == ("PNG", size), name
            ink = (np.asarray(png.convert("L")) < 200).mean()
            assert 0.01 < ink < 0.5, (name, ink)  # drawn, neither blank nor filled
    ap = pd.read_csv(out / "aperture_profiles.csv")
    own = ap[ap["condition"] == "model:grasp-1.0s"]
    assert len(own) == 101 and 0.11 < own["mean"].max() < 0.13  # the model's own opening
    prof = pd.read_csv(out / "condition_profiles.csv")
    np.testing.assert_allclose(prof["transport_mean"] + prof["grip_mean"], prof["mean"])
    page = (out / "report.html").read_text()
    assert "Verdicts per condition" in page and 'href="normal-0.recognition.json"' in page
    assert 'href="#clip-0"' in page and 'id="clip-0"' in page


def test_the_pages_other_columns_are_summary_csvs_values(scored, tmp_path):
    # the folded table says it shows summary.csv's columns: it shows them in that file's
    # units (ms, mm, %), not the in-memory table's SI ones (a movement time of 1.73 beside
    # summary.csv's 1725)
    import re

    out, recs = scored
    results = [ClipResult(n, c, "ok", summary=ClipSummary.from_recognition(r))
               for n, (r, c) in recs.items()]
    write_batch_report(summary_table(results), {r.clip: r.summary for r in results}, tmp_path)
    page = (tmp_path / "report.html").read_text()
    table = page.split("other columns of summary.csv", 1)[1].split("</table>", 1)[0]
    rows = [re.findall(r"<t[hd][^>]*>(.*?)</t[hd]>", r) for r in table.split("<tr>")[1:]]
    shown = pd.DataFrame(rows[1:], columns=[h.split(" (")[0] for h in rows[0]]).set_index("clip")
    assert "movement_time (ms)" in rows[0] and "mga (mm)" in rows[0]  # each with its unit
    written = pd.read_csv(tmp_path / "summary.csv").set_index("clip")
    for column in ("movement_time", "peak_speed", "peak_speed_time", "mga", "mga_time"):
        assert written[column].notna().all()
        np.testing.assert_allclose(shown[column].astype(float), written.loc[shown.index, column],
                                   rtol=6e-3, err_msg=column)  # shown to 3 digits


def test_the_pages_other_columns_show_whole_milliseconds_without_an_exponent():
    from perception.report.batch import _other_columns_table

    summary = pd.DataFrame({"clip": ["a"], "status": ["ok"], "movement_time": [1.4417],
                            "peak_speed": [0.942], "mga_time": [0.3083]})
    table = "".join(_other_columns_table(summary))
    assert "<td class=n>1442</td><td class=n>942</td><td class=n>30.8</td>" in table
    assert "e+" not in table  # 1.44e+03 ms


def test_a_batch_draws_its_figures_without_pyplot(tmp_path):
    """``hammer-mv batch`` on tracks files, in a fresh process: the figures are drawn by
    matplotlib on Agg canvases, never through pyplot (its global figure registry)."""
    src = tmp_path / "src"
    src.mkdir()
    rows = []
    for i, cond in enumerate(["normal", "normal", "delayed", "reach"]):
        demo_tracks(cond, i)[0].save(src / f"{cond}-{i}.tracks.h5")
        rows.append(f"{cond}-{i},{cond}-{i}.tracks.h5,{cond}\n")
    (src / "manifest.csv").write_text("clip,video,condition\n" + "".join(rows))
    repfile = default_repertoire().save(tmp_path / "rep.h5")
    out = tmp_path / "out"
    code = ("import sys\nfrom hammer_mv.cli import main\n"
            f"rc = main(['batch', {str(src / 'manifest.csv')!r}, '-o', {str(out)!r}, "
            f"'--repertoire', {str(repfile)!r}, '--quiet'])\n"
            "print(rc, 'matplotlib.figure' in sys.modules, 'matplotlib.pyplot' in sys.modules)\n")
    root = str(Path(__file__).resolve().parents[1])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([root, os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["0", "True", "False"], proc.stdout + proc.stderr
    for name, size in FIGURES.items():
        with Image.open(out / name) as png:
            assert png.size == size, name


#: Names from the outside world (issue 12): each would break an attribute, a tag, a link or
#: a URL if written raw. File names cannot hold "/", so none here does.
HOSTILE = ('a" onerror="alert(1)" x=', "50% #1?", "<b>x", "<img src=x onerror=alert(2)>",
           "grasp é 日本 &amp;")


@pytest.mark.filterwarnings("error::UserWarning")
def test_hostile_clip_names_are_escaped_in_the_page_and_their_links_resolve(tmp_path):
    from html.parser import HTMLParser
    from urllib.parse import unquote, urlsplit

    rep = default_repertoire()
    results = []
    for i, name in enumerate(HOSTILE):
        cond = ("normal", "delayed")[i % 2]
        rec = recognize_clip(demo_tracks(cond, i)[0], rep, clip=name)
        write_clip_report(rec, tmp_path, extra={"condition": cond})
        results.append(ClipResult(name, cond, "ok", summary=ClipSummary.from_recognition(rec)))
    results.append(ClipResult('<i>bad" x=', "normal", "failed", error='<script>"x"</script>'))
    summary = summary_table(results)
    write_batch_report(summary, {r.clip: r.summary for r in results if r.summary}, tmp_path,
                       models=rep.models)

    class Page(HTMLParser):
        def __init__(self):
            super().__init__()
            self.tags, self.attrs, self.text, self.h3 = [], [], [], []
            self._in_h3 = False

        def handle_starttag(self, tag, attrs):
            self.tags.append(tag)
            self.attrs += [(tag, k, v) for k, v in attrs]
            self._in_h3 = tag == "h3"

        def handle_endtag(self, tag):
            self._in_h3 = False if tag == "h3" else self._in_h3

        def handle_data(self, data):
            self.text.append(data)
            if self._in_h3:
                self.h3.append(data)

    page = Page()
    page.feed((tmp_path / "report.html").read_text(encoding="utf-8"))
    # no tag or attribute came from a name: only those the writer makes
    assert set(page.tags) <= {"html", "head", "meta", "title", "style", "body", "h1", "h2", "h3",
                              "p", "span", "b", "i", "a", "img", "table", "thead", "tbody", "tr",
                              "th", "td", "div", "figure", "figcaption", "details", "summary",
                              "code", "br", "small"}, set(page.tags)
    assert {k for _, k, _ in page.attrs} <= {"charset", "name", "content", "class", "id",
                                             "href", "src", "alt", "loading"}
    assert not any(t == "img" and k == "src" and v == "x" for t, k, v in page.attrs)
    # each name shows as itself (the parser unescapes the text)
    assert page.h3 == list(HOSTILE)
    text = "".join(page.text)
    assert '<i>bad" x=' in text and '<script>"x"</script>' in text
    # every link and image names an existing file once unquoted; in-page anchors exist
    ids = {v for _, k, v in page.attrs if k == "id"}
    targets = [v for _, k, v in page.attrs if k in ("href", "src")]
    assert len(targets) > 4 * len(HOSTILE)
    for url in targets:
        if url.startswith("#"):
            assert url[1:] in ids, url
            continue
        parts = urlsplit(url)
        assert not (parts.scheme or parts.netloc or parts.query or parts.fragment), url
        assert (tmp_path / unquote(parts.path)).is_file(), url
    for name in HOSTILE:
        for suffix in (".recognition.json", ".confidence.csv", ".confidence.png", ".paths.png"):
            assert name + suffix in {unquote(u) for u in targets}, (name, suffix)


def test_a_table_written_by_write_csv_reads_back_the_same(tmp_path):
    from perception.io.atomic import write_csv

    rng = np.random.default_rng(0)
    x = np.concatenate([rng.normal(size=40) * 10.0 ** rng.integers(-20, 20, 40),
                        [np.nan, np.inf, -np.inf, -0.0, 1e-5, 0.1, 1 / 3, 1e16]])
    cols = {"time": x, "frame": np.arange(x.size), "ok": np.arange(x.size) % 2 == 0,
            "model": np.array(["a,b", 'say "x"', "é ü"] * 16), "C": x[::-1].copy()}
    write_csv(tmp_path / "ours.csv", pd.DataFrame(cols))
    back = pd.read_csv(tmp_path / "ours.csv")
    pd.testing.assert_frame_equal(back, pd.DataFrame(cols))  # round trip, NaN and -0.0 included
    np.testing.assert_array_equal(np.signbit(back["time"]), np.signbit(x))
    # the columns alone (recognize's confidence table) are written as pandas writes them
    write_csv(tmp_path / "columns.csv", cols)
    assert (tmp_path / "columns.csv").read_bytes() == (tmp_path / "ours.csv").read_bytes()


def test_the_clip_csv_is_its_columns_as_pandas_writes_them(scored, tmp_path):
    # written from Python's numbers (not NumPy's): the same text as the columns themselves
    out, recs = scored
    for name, (rec, _) in recs.items():
        pd.DataFrame(rec.columns()).to_csv(tmp_path / "pandas.csv", index=False)
        assert ((out / f"{name}.confidence.csv").read_bytes()
                == (tmp_path / "pandas.csv").read_bytes()), name


def _old_f_oneway(groups):
    """The batch's ANOVA before it called scipy.stats (on scipy.special)."""
    from scipy.special import fdtrc

    everything = np.concatenate(groups)
    k, n, grand = len(groups), everything.size, everything.mean()
    between = sum(len(g) * (g.mean() - grand) ** 2 for g in groups) / (k - 1)
    within = sum(((g - g.mean()) ** 2).sum() for g in groups) / (n - k)
    if within == 0:
        return (np.nan, np.nan) if between == 0 else (np.inf, 0.0)
    return between / within, fdtrc(k - 1, n - k, between / within)


def _old_welch_t(a, b):
    """The batch's Welch t-test before it called scipy.stats (on scipy.special)."""
    from scipy.special import stdtr

    va, vb = a.var(ddof=1) / len(a), b.var(ddof=1) / len(b)
    df = (va + vb) ** 2 / (va ** 2 / (len(a) - 1) + vb ** 2 / (len(b) - 1))
    t = (a.mean() - b.mean()) / np.sqrt(va + vb)
    return t, 2 * stdtr(df, -np.abs(t)), df


def test_the_batch_statistics_equal_the_former_ones():
    rng = np.random.default_rng(1)
    for _ in range(30):
        sizes = rng.integers(2, 15, 3)
        conf = [rng.normal(m, s, n) for n, s, m in zip(sizes, rng.uniform(0.1, 3, 3),
                                                      rng.normal(size=3))]
        summary = pd.DataFrame({"status": "ok", "condition": np.repeat(list("abc"), sizes),
                                "conf_m": np.concatenate(conf)})
        stats = condition_statistics(summary, "m")
        assert list(stats["test"]) == ["one-way ANOVA", *["Welch t-test"] * 3]
        np.testing.assert_allclose(stats.iloc[0][["statistic", "p_value"]].to_numpy(float),
                                   _old_f_oneway(conf), rtol=1e-9)
        for row, (i, j) in zip(stats.iloc[1:].itertuples(), [(0, 1), (0, 2), (1, 2)]):
            t, p, df = _old_welch_t(conf[i], conf[j])
            np.testing.assert_allclose([row.statistic, row.p_value], [t, p], rtol=1e-9)
            assert row.df == f"{df:.1f}"
        assert stats.iloc[0]["n_per_group"] == ", ".join(
            f"{c}={n}" for c, n in zip("abc", sizes))
        assert (stats["note"] == "a group has fewer than 3 clips").tolist() == [
            min(sizes) < 3, *[min(sizes[i], sizes[j]) < 3 for i, j in [(0, 1), (0, 2), (1, 2)]]]


def test_statistics_of_constant_groups_are_nan_or_inf_silently():
    import warnings

    summary = pd.DataFrame({"status": "ok", "condition": list("aaabbbbcc"),
                            "conf_m": [1.0] * 3 + [2.0] * 4 + [1.0] * 2})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        stats = condition_statistics(summary, "m").set_index("groups")
    assert stats.loc["a / b / c", "statistic"] == np.inf
    assert stats.loc["a / b / c", "p_value"] == 0.0
    assert np.isnan(stats.loc["a vs c", "statistic"]) and np.isnan(stats.loc["a vs c", "p_value"])
    assert stats.loc["a vs c", "n_per_group"] == "a=3, c=2"
