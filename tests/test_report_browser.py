"""report.html in a real (headless) browser: it loads, shows its figures, its main table fits.

Chromium is driven from the command line (``--dump-dom``, ``--screenshot``),
so no Python driver is needed. Outside CI the test skips when no Chromium is
installed; in CI (``CI=true``) a missing Chromium fails it: ``.ci/run``
installs it.
"""

from __future__ import annotations

import html
import os
import re
import shutil
import subprocess

import numpy as np
import pytest
from _demos import default_repertoire, demo_tracks

from perception.batch import ClipResult, summary_table
from perception.pipeline import recognize_clip
from perception.report import ClipSummary, write_batch_report, write_clip_report

pytestmark = pytest.mark.slow

#: A clip name that would break out of an attribute, a link and a URL if not escaped.
NASTY = 'a" onerror="alert(1)" x=#1%20'
#: More names from the outside world: a query, a fragment and a percent sign in a URL, a tag
#: with a script, non-ASCII.
PERCENT = "50% #1? é"
TAG = "<img src=x onerror=alert(2)>"
WIDTH, HEIGHT = 1280, 900


def _chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        found = shutil.which(name)
        if found:
            return found
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail("no Chromium in CI: .ci/run must install it (apt-get install chromium)")
    pytest.skip("no Chromium installed (apt-get install chromium); CI runs this test")


def _run(browser: str, profile, *args: str) -> str:
    flags = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             "--hide-scrollbars", f"--user-data-dir={profile}", f"--window-size={WIDTH},{HEIGHT}",
             "--virtual-time-budget=10000"]
    done = subprocess.run([browser, *flags, *args], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """A batch report of five scored clips (three with hostile names) and a failed one."""
    out = tmp_path_factory.mktemp("report")
    rep = default_repertoire()
    results = []
    for i, (name, cond) in enumerate(((NASTY, "normal"), (PERCENT, "normal"),
                                      (TAG, "open-close-open"),
                                      ("open-close-open-02", "open-close-open"),
                                      ("reach-01", "reach"))):
        rec = recognize_clip(demo_tracks(cond, i)[0], rep, clip=name)
        write_clip_report(rec, out, extra={"condition": cond})
        results.append(ClipResult(name, cond, "ok", summary=ClipSummary.from_recognition(rec)))
    results.append(ClipResult("broken", "normal", "failed", error="empty.mp4: not a video"))
    summary = summary_table(results)
    write_batch_report(summary, {r.clip: r.summary for r in results if r.summary}, out,
                       models=rep.models)
    return out


_PROBE = """
<script>
window.addEventListener('load', () => {
  const main = document.querySelector('table.t.main');
  const imgs = Array.from(document.images);
  const out = document.createElement('pre');
  out.id = 'probe';
  out.textContent = JSON.stringify({
    viewport: window.innerWidth,
    page: document.documentElement.scrollWidth,
    table_right: main ? main.getBoundingClientRect().right : -1,
    images: imgs.length,
    loaded: imgs.filter(i => i.complete && i.naturalWidth > 0).length,
    injected: document.querySelectorAll('[onerror]').length,
    alerts: window.__alerts || 0,
    clip_ids: Array.from(document.querySelectorAll('.clip h3')).map(h => h.textContent),
  });
  document.body.appendChild(out);
});
window.alert = () => { window.__alerts = (window.__alerts || 0) + 1; };
</script>
"""


def test_the_page_loads_with_its_figures_and_the_main_table_fits(report, tmp_path):
    import json

    browser = _chromium()
    page = (report / "report.html").read_text()
    probe = report / "probe.html"  # beside the report, so its relative links resolve
    probe.write_text(page.replace("<head>", "<head>" + _PROBE, 1))
    dom = _run(browser, tmp_path / "profile", "--dump-dom", probe.as_uri())
    found = re.search(r'<pre id="probe">(.*?)</pre>', dom, re.S)
    assert found, "the page did not finish loading"
    m = json.loads(html.unescape(found.group(1)))
    assert m["viewport"] == WIDTH
    assert 0 < m["table_right"] <= WIDTH, m  # the main table fits a 1280 px window
    assert m["page"] <= WIDTH, m  # and nothing else widens the page
    # every figure: 2 kinematics and 4 chapter 5 of the batch, 3 per clip (confidence, paths,
    # kinematics)
    assert m["images"] == 6 + 3 * 5 and m["loaded"] == m["images"], m
    assert m["injected"] == 0 and m["alerts"] == 0, m
    assert {NASTY, PERCENT, TAG} <= set(m["clip_ids"]), m["clip_ids"]


def test_a_screenshot_shows_the_report(report, tmp_path):
    from matplotlib.image import imread

    browser = _chromium()
    shot = tmp_path / "report.png"
    _run(browser, tmp_path / "profile", f"--screenshot={shot}", (report / "report.html").as_uri())
    img = imread(shot)
    assert img.shape[:2] == (HEIGHT, WIDTH)
    # not a blank page: text and tables make many distinct rows
    grey = img[..., :3].mean(axis=2)
    assert (grey.std(axis=1) > 0.02).sum() > HEIGHT // 4
    assert np.mean(grey < 0.5) > 0.005  # some dark ink (text)


def test_links_and_names_are_escaped_and_quoted(report):
    page = (report / "report.html").read_text()
    for name in (NASTY, TAG):
        assert name not in page  # never raw
    assert 'onerror="alert' not in page and "<img src=x" not in page
    assert "50%25%20%231%3F%20%C3%A9.paths.png" in page  # quoted, UTF-8
    assert "a%22%20onerror%3D%22alert%281%29%22%20x%3D%231%2520.recognition.json" in page
    for name in ("summary.csv", "statistics.csv", "aperture_profiles.png", "confidence_single.png",
                 "confidence_all.png", "condition_profiles.png", "reach-01.recognition.json",
                 "reach-01.confidence.csv"):
        assert f'href="{name}"' in page, name
