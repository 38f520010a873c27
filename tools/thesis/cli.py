"""Regenerate the thesis's figures and a table of its quantitative claims beside ours.

    python -m tools.thesis [-o out/thesis] [--trials N] [--seed N] [--quick]
                           [--skip-ch4] [--skip-ch5] [--skip-verdict] [--jobs N]

(``tools/reproduce_thesis.py`` is the same command; ``make reproduce`` runs it.)
Writes, into the output folder, every figure of chapter 2 (2.5-2.8), chapter 3
(3.2-3.9), appendix A (A.1-A.3) and chapter 4 (4.1-4.16) as PNG named after the
thesis figure (``fig3_5_speed_accuracy.png``), CSV tables beside the figures that
have numbers, chapter 5 from rendered video in ``ch5/`` (not with ``--quick``), and
``numbers.md``: per chapter, one row per quantitative claim of the thesis — the
claim, where the thesis makes it (section, figure, line of the thesis text), the
measure it is judged by, the thesis's value, ours, the verdict (agree / differs /
by construction / thesis inconsistent) and why — then a sensitivity table for each
parameter the thesis leaves open that a verdict depends on. ``numbers.csv`` holds
the claims (with each claim's id and its rule, ``expected``). Every file is
written to a temporary name and renamed when complete.

``--trials`` sets the Monte Carlo repetitions everywhere (default: the thesis's
counts, 500 per setting in chapter 4); ``--quick`` is a smoke run (10 repetitions,
one observed movement per test trajectory in Fig. A.1); ``--jobs N`` runs N
chapters at once, each in its own process (default 2; the numbers do not depend on
it). Exit status: 0 when every chapter ran, 1 when one failed (numbers.md says
which), 2 on bad options.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import pandas as pd
from tqdm import tqdm

from perception.io.atomic import write_csv, write_text
from tools.thesis.markdown import claim_counts, n_claims, numbers_markdown
from tools.thesis.records import CLAIM_KEYS, as_claim, is_sensitivity

log = logging.getLogger("tools.thesis")

ROOT = Path(__file__).resolve().parents[2]
#: (title, module) in the order of the thesis; each module's ``reproduce(out, *,
#: trials, seed, quick, progress)`` writes its figures and returns its records.
CHAPTERS = (
    ("Chapter 2", "tools.thesis.ch2"),
    ("Chapter 3", "tools.thesis.ch3"),
    ("Appendix A", "tools.thesis.appendix_a"),
    ("Chapter 4", "tools.thesis.ch4"),
    ("Chapter 5", "tools.thesis.ch5"),
)
QUICK_TRIALS = 10


def load_chapter(module: str):
    """The ``reproduce`` function of a chapter module.

    Parameters
    ----------
    module : str
        Module name (e.g. ``"tools.thesis.ch4"``).
    """
    return importlib.import_module(module).reproduce


def run_chapter(
    title: str, module: str, out: Path, *, trials: int | None, seed: int, quick: bool,
    progress=None,
) -> tuple[list[dict], str | None, float, bool]:
    """Run one chapter into ``out``.

    Parameters
    ----------
    title : str
        The chapter's title in numbers.md.
    module : str
        Its module.
    out : Path
        Output folder.
    trials : int or None
        Repetitions everywhere (None: the thesis's counts).
    seed : int
        Base seed.
    quick : bool
        Smoke run (fewer observed movements in appendix A).
    progress : callable, optional
        Called with the name of each figure as it starts.

    Returns
    -------
    records : list of dict
        Its claims and tables, each given ``chapter=title``.
    note : str or None
        How it failed.
    seconds : float
        How long it took.
    ok : bool
        False if it failed.
    """
    start = time.perf_counter()
    try:
        got = load_chapter(module)(out, trials=trials, seed=seed, quick=quick,
                                   progress=progress or (lambda name: None))
        return [dict(r, chapter=title) for r in got], None, time.perf_counter() - start, True
    except Exception as exc:  # report and go on with the other chapters
        log.exception("%s failed", title)
        return ([], f"{title} FAILED: {type(exc).__name__}: {exc}",
                time.perf_counter() - start, False)


def run(
    out: Path, *, trials: int | None, seed: int, quick: bool, chapters=CHAPTERS, jobs: int = 1
) -> tuple[list[dict], list[str], list[str], bool]:
    """Run every chapter into ``out``, in this process or in ``jobs`` worker processes.

    Parameters
    ----------
    out : Path
        Output folder.
    trials : int or None
        Repetitions everywhere (None: the thesis's counts).
    seed : int
        Base seed.
    quick : bool
        Smoke run: few repetitions everywhere.
    chapters : sequence of (title, module)
        Which chapters to run.
    jobs : int
        Chapters run at once, each in its own process (1: one after the other,
        here). Every chapter draws from its own seeds, so the results do not
        depend on it.

    Returns
    -------
    claims, notes, timings : lists
        Every chapter's records (claims and sensitivity tables, each given the
        chapter's title as ``chapter``), in the order of ``chapters``; notes on
        failed chapters; a timing line per chapter.
    ok : bool
        False if a chapter failed.
    """
    if quick and trials is None:
        trials = QUICK_TRIALS
    kw = dict(trials=trials, seed=seed, quick=quick)
    bar = tqdm(total=len(chapters), unit="chapter", disable=not sys.stderr.isatty())
    results = {}
    if jobs <= 1 or len(chapters) < 2:
        for title, module in chapters:
            bar.set_description(title)
            results[title] = run_chapter(title, module, out, **kw,
                                         progress=lambda name: bar.set_postfix_str(name))
            bar.update()
    else:
        # the later chapters take longest: start them first so the workers finish together
        with ProcessPoolExecutor(max_workers=min(jobs, len(chapters))) as pool:
            futures = {pool.submit(run_chapter, title, module, out, **kw): title
                       for title, module in reversed(chapters)}
            for f in as_completed(futures):
                results[futures[f]] = f.result()
                bar.set_description(futures[f])
                bar.update()
    bar.close()
    claims, notes, timings, ok = [], [], [], True
    for title, _ in chapters:
        records, note, seconds, fine = results[title]
        claims += records
        notes += [note] if note else []
        timings.append(f"{title}: {seconds:.1f} s")
        ok = ok and fine
    return claims, notes, timings, ok


def main(argv: list[str] | None = None) -> int:
    """Command line entry point; returns the exit status.

    Parameters
    ----------
    argv : list of str, optional
        Arguments (default: ``sys.argv[1:]``).
    """
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("-o", "--out", type=Path, default=ROOT / "out" / "thesis",
                        help="output folder (default: out/thesis)")
    parser.add_argument("--trials", type=int, default=None, metavar="N",
                        help="Monte Carlo repetitions everywhere (default: the thesis's)")
    parser.add_argument("--seed", type=int, default=0, metavar="N", help="base seed (default 0)")
    parser.add_argument("--quick", action="store_true",
                        help=f"smoke run: {QUICK_TRIALS} repetitions unless --trials is given")
    parser.add_argument("--skip-ch4", action="store_true", help="do not run chapter 4")
    parser.add_argument("--skip-ch5", action="store_true",
                        help="do not run chapter 5 (--quick skips it too: it renders video)")
    parser.add_argument("--skip-verdict", action="store_true",
                        help="do not evaluate the verdict on the held-out population "
                             "(--quick skips it too: it renders and tracks 60 clips)")
    parser.add_argument("--jobs", type=int, default=2, metavar="N",
                        help="chapters run at once, each in its own process (default 2; "
                             "results do not depend on it)")
    args = parser.parse_args(argv)
    if args.trials is not None and args.trials < 2:
        parser.error("--trials must be at least 2 (standard deviations need two)")
    if args.jobs < 1:
        parser.error("--jobs must be at least 1")
    logging.basicConfig(level=logging.WARNING, format="%(name)s: %(message)s")

    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    skip_ch5 = args.skip_ch5 or args.quick
    chapters = [c for c in CHAPTERS if not (args.skip_ch4 and c[0] == "Chapter 4")
                and not (skip_ch5 and c[0] == "Chapter 5")]
    start = time.perf_counter()
    claims, notes, timings, ok = run(
        out, trials=args.trials, seed=args.seed, quick=args.quick, chapters=chapters,
        jobs=args.jobs,
    )
    if args.skip_ch4:
        notes.insert(0, "Chapter 4: skipped (--skip-ch4).")
    if skip_ch5:
        notes.insert(0, "Chapter 5: skipped (" + ("--skip-ch5" if args.skip_ch5 else
                                                  "--quick: it renders and tracks video") + ").")
    total = time.perf_counter() - start
    header = [
        f"Generated by `python -m tools.thesis` (seed {args.seed}; repetitions: "
        + (f"{args.trials}" if args.trials else "the thesis's" if not args.quick
           else f"{QUICK_TRIALS} (--quick)")
        + f"); {total:.0f} s in all, {args.jobs} chapter(s) at a time "
        f"({'; '.join(timings)}).",
        "Each claim names the measure it is judged by; the why column says how the verdict "
        "follows and, where ours differs, why. Figures and CSV tables are beside this file.",
    ]
    rows = [dict(as_claim(r), chapter=r["chapter"]) for r in claims if not is_sensitivity(r)]
    write_csv(out / "numbers.csv", pd.DataFrame(rows, columns=["chapter", *CLAIM_KEYS]))
    text = numbers_markdown(claims, notes, header)
    if not (args.skip_verdict or args.quick):
        # not a thesis claim: how the verdict does on movements our models did not
        # make, a population held out from every choice of a parameter
        sys.path.insert(0, str(ROOT / "tools"))
        import evaluate_verdict

        _, result = evaluate_verdict.run("heldout", out / "verdict",
                                         evaluate_verdict.DEFAULT_COUNTS, jobs=args.jobs,
                                         quiet=True)
        text += "\n" + result["markdown"]
    write_text(out / "numbers.md", text)
    figures = sorted(p.name for p in out.glob("fig*.png"))
    thesis = [r for r in rows if r["kind"] == "thesis"]
    print(f"{len(figures)} figures, {n_claims(thesis).replace('claims', 'thesis claims', 1)} "
          f"({claim_counts(thesis)}), "
          f"{len(rows) - len(thesis)} own checks in {out} "
          f"({total:.0f} s)")
    for n in notes:
        print(n)
    return 0 if ok else 1
