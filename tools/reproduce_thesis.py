"""Regenerate the thesis's figures and a table of its quantitative claims beside ours.

    python tools/reproduce_thesis.py [-o out/thesis] [--trials N] [--seed N] [--quick]
                                     [--skip-ch4] [--skip-ch5] [--jobs N]

Writes, into the output folder, every figure of chapter 2 (2.5-2.8), chapter 3
(3.2-3.9) and appendix A (A.1-A.3) as PNG named after the thesis figure
(``fig3_5_speed_accuracy.png``), CSV tables beside the figures that have
numbers, the chapter 4 figures when ``tools/reproduce_ch4.py`` exists, chapter 5
from rendered video in ``ch5/`` (``tools/reproduce_ch5.py``; not with
``--quick``), and ``numbers.md``: per chapter, one row per quantitative claim of the thesis —
the claim, where the thesis makes it (section, figure, line of the thesis
text), the measure it is judged by, the thesis's value, ours, the verdict
(agree / differs / by construction / thesis inconsistent) and why — then a
sensitivity table for each parameter the thesis leaves open that a verdict
depends on. ``numbers.csv`` holds the claims. Every file is written to a
temporary name and renamed when complete.

``--trials`` sets the Monte Carlo repetitions everywhere (default: the
thesis's counts, 500 per setting in chapter 4); ``--quick`` is a smoke run
(10 repetitions, one observed movement per test trajectory in Fig. A.1);
``--jobs N`` runs N chapters at once, each in its own process (default 2:
chapter 4 beside the others; the numbers do not depend on it).
Exit status: 0 when every chapter ran, 1 when one failed (numbers.md says
which), 2 on bad options.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import logging
import sys
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for _p in (ROOT, ROOT / "tools"):
    if str(_p) not in sys.path:
        sys.path.insert(0, str(_p))

import pandas as pd  # noqa: E402
from reproduce_common import (  # noqa: E402
    CLAIM_KEYS,
    OWN_HEADINGS,
    OWN_KEYS,
    TABLE_HEADINGS,
    TABLE_KEYS,
    VERDICTS,
    as_claim,
    is_sensitivity,
    settings_rows,
)
from tqdm import tqdm  # noqa: E402

from perception.io.atomic import write_csv, write_text  # noqa: E402

log = logging.getLogger("reproduce_thesis")

#: (title, module in tools/) in the order of the thesis.
CHAPTERS = (
    ("Chapter 2", "reproduce_ch2"),
    ("Chapter 3", "reproduce_ch3"),
    ("Appendix A", "reproduce_appendix_a"),
    ("Chapter 4", "reproduce_ch4"),
    ("Chapter 5", "reproduce_ch5"),
)
#: Chapters 4 and 5 are written separately; the run goes on without them.
OPTIONAL = {"reproduce_ch4", "reproduce_ch5"}
QUICK_TRIALS = 10
CH4_TRIALS = 500
#: Chapter 5: clips per condition and generator (rendered, tracked, recognised).
CH5_CLIPS = 10


def load_chapter(module: str) -> Callable | None:
    """The ``reproduce`` function of a chapter module in tools/, or None if the module is absent.

    Parameters
    ----------
    module : str
        Module name (e.g. ``"reproduce_ch4"``). A module that exists but fails
        to import raises, so a broken chapter is never mistaken for a missing one.
    """
    if importlib.util.find_spec(module) is None:
        return None
    return importlib.import_module(module).reproduce


def _cell(value) -> str:
    return str(value).replace("|", "\\|").replace("\n", " ")


def _row(cells) -> str:
    return "| " + " | ".join(_cell(c) for c in cells) + " |"


#: The verdicts numbers.md tallies, in order: :data:`VERDICTS` with ``conditional``
#: (a verdict that flips with a choice the thesis leaves open) after ``differs``.
TALLIED = (*VERDICTS[:2], "conditional", *VERDICTS[2:])
_WORDS = {"agree": "agree", "differs": "differ", "conditional": "conditional",
          "by construction": "by construction", "thesis inconsistent": "thesis inconsistent"}


def _tally(words: list[str]) -> str:
    """``"37 agree, 5 differ, 0 conditional, ..."``: every tallied verdict, then any other."""
    n = pd.Series(words, dtype=object).value_counts()
    extra = [w for w in n.index if w not in TALLIED]
    return ", ".join([f"{int(n.get(v, 0))} {_WORDS[v]}" for v in TALLIED]
                     + [f"{int(n[w])} {w}" for w in extra])


def verdict_counts(claims: list[dict]) -> str:
    """``"37 agree, 5 differ, ..."`` over the claims, in the order of :data:`TALLIED`.

    Parameters
    ----------
    claims : list of dict
        Claim records (current form).
    """
    return _tally([c["verdict"] for c in claims])


def _sensitivity_md(table: dict) -> list[str]:
    lines = [f"#### Sensitivity: {table['title']}", "",
             f"Thesis: {table['location']}. {table['note']}", ""]
    lines.append(_row(table["columns"]))
    lines.append("|" + "---|" * len(table["columns"]))
    lines += [_row(r) for r in table["rows"]]
    return lines + [""]


def _table(rows: list[dict], keys, headings) -> list[str]:
    lines = [_row(headings), "|" + "---|" * len(headings)]
    for c in rows:
        cells = [c[k] for k in keys]
        cells[keys.index("measure")] = c["measure"] or "not stated"
        if c["verdict"] != "agree":
            cells[keys.index("verdict")] = f"**{c['verdict']}**"
        lines.append(_row(cells))
    return lines + [""]


def at_thesis_verdict(text: str, verdict: str | None = None) -> str:
    """The verdict word of an ``at_thesis`` cell (``conditional`` for tip_start-dependent rows).

    A row that is ``by construction`` at our settings is so at the thesis's too:
    what makes it hold is how the model or the test was built, not the settings,
    so it never enters an agree tally in either column.

    Parameters
    ----------
    text : str
        The cell, e.g. ``"agree (survives text, printed): ..."``, ``"printed: agree: ..."``
        or ``"r = 0.002, w_v = 0.1: differs: ..."``.
    verdict : str, optional
        The row's verdict at our settings.
    """
    if verdict == "by construction":
        return verdict
    text = str(text)
    if text.startswith("conditional"):
        return "conditional"
    for prefix in ("printed: ", "r = 0.002, w_v = 0.1: "):
        text = text[len(prefix):] if text.startswith(prefix) else text
    return text.split(":")[0].split(" (")[0].strip() or "not computed"


#: Prefixes of a row that measures the same statement as another row another way (the
#: hand frame beside the world frame): one claim, counted once.
VARIANT_PREFIXES = ("Hand frame: ",)


def claim_key(c: dict) -> tuple[str, str]:
    """What makes two rows one thesis claim: the chapter and the statement, less any
    :data:`VARIANT_PREFIXES` (case ignored).

    Parameters
    ----------
    c : dict
        A claim record (with ``chapter`` where it has one).
    """
    text = str(c["claim"])
    for prefix in VARIANT_PREFIXES:
        text = text[len(prefix):] if text.startswith(prefix) else text
    return str(c.get("chapter", "")), text.strip().lower()


def unique_verdicts(claims: list[dict], column) -> list[str]:
    """One verdict per thesis claim (:func:`claim_key`): its rows' verdict where they
    agree, ``conditional`` where the variants disagree (the verdict depends on how the
    statement is measured, e.g. the frame).

    Parameters
    ----------
    claims : list of dict
        Claim records.
    column : callable
        A row's verdict in the column tallied (``lambda c: c["verdict"]``).
    """
    groups: dict[tuple, list[str]] = {}
    for c in claims:
        groups.setdefault(claim_key(c), []).append(column(c))
    return [v[0] if len(set(v)) == 1 else "conditional" for v in groups.values()]


def at_thesis_counts(claims: list[dict]) -> str:
    """``"20 agree, 9 differ, ..."``: the verdicts at the thesis's settings (first word).

    Parameters
    ----------
    claims : list of dict
        Thesis claims (current form).
    """
    return _tally(unique_verdicts(
        claims, lambda c: at_thesis_verdict(c.get("at_thesis", ""), c["verdict"])))


def claim_counts(claims: list[dict]) -> str:
    """``"37 agree, 5 differ, ..."`` over the unique thesis claims at our settings.

    Parameters
    ----------
    claims : list of dict
        Thesis claims (current form).
    """
    return _tally(unique_verdicts(claims, lambda c: c["verdict"]))


def _n_claims(claims: list[dict]) -> str:
    n, rows = len({claim_key(c) for c in claims}), len(claims)
    return f"{n} claims" + (f" ({rows} rows: a hand-frame row beside its world-frame row is "
                            "one claim)" if rows != n else "")


def numbers_markdown(records: list[dict], notes: list[str], header: list[str]) -> str:
    """numbers.md: a header, the settings, and per chapter its thesis claims, our own
    checks and sensitivity tables, then every verdict at both settings side by side.

    Parameters
    ----------
    records : list of dict
        Claims (:func:`reproduce_common.claim`, or the original six-key
        record) and sensitivity tables (:func:`reproduce_common.sensitivity`),
        each with a ``chapter`` title (records without one are listed under
        "Claims").
    notes : list of str
        Lines about the run (missing or failed chapters), shown above the tables.
    header : list of str
        Lines describing the run (options, timings).
    """
    claims = [as_claim(r) for r in records if not is_sensitivity(r)]
    thesis = [c for c in claims if c["kind"] == "thesis"]
    own = [c for c in claims if c["kind"] == "own"]
    lines = ["# Thesis claims beside ours", "", *header, ""]
    lines += [f"- {n}" for n in notes]
    lines += [f"- {_n_claims(thesis).replace('claims', 'thesis claims', 1)}, each counted "
              "once (chapter 5's on the independent generator's clips; on the model's own "
              "stimuli they are our own checks).",
              f"  - at our settings: {claim_counts(thesis)};",
              f"  - at the thesis's settings: {at_thesis_counts(thesis)}.",
              f"- {len(own)} checks of our own (not thesis claims): {verdict_counts(own)}.",
              ""]
    lines += ["Verdicts: **agree** — ours supports the statement by the measure given; "
              "**differs** — it does not; **by construction** — it holds only because of "
              "how the model or the test was built (in both columns: it never enters an agree "
              "tally); **conditional** — the verdict flips with a choice the thesis leaves "
              "open (geometry it does not give, a reading of eqs. 5.1/5.7 it allows), with "
              "the range where it holds; **thesis inconsistent** — the thesis "
              "says two different things (both places are cited). A thesis claim names the "
              "line of the thesis text it quotes and the words; 'at the thesis's settings' "
              "is the verdict (and our value) with the thesis's model and cost weights "
              "(chapter 5: the repertoire planned with them). Chapter 5's rows are judged "
              "under every reading of eqs. 5.1/5.7 the thesis allows, and say which they "
              "survive.",
              "", "## Settings: the thesis's and ours", ""]
    lines += [_row(("parameter", "thesis", "ours", "effect on the rows")),
              "|---|---|---|---|", *[_row(r) for r in settings_rows()], ""]
    chapters = list(dict.fromkeys(r.get("chapter", "Claims") for r in records))
    for chapter in chapters:
        mine = [r for r in records if r.get("chapter", "Claims") == chapter]
        rows = [as_claim(r) for r in mine if not is_sensitivity(r)]
        lines += [f"## {chapter}", ""]
        mine_thesis = [c for c in rows if c["kind"] == "thesis"]
        mine_own = [c for c in rows if c["kind"] == "own"]
        if mine_thesis:
            lines += [f"### Thesis claims ({chapter})", "",
                      f"{_n_claims(mine_thesis)}: {claim_counts(mine_thesis)}; at the "
                      f"thesis's settings: {at_thesis_counts(mine_thesis)}.", ""]
            lines += _table(mine_thesis, TABLE_KEYS, TABLE_HEADINGS)
        if mine_own:
            lines += [f"### Our own checks ({chapter}; not thesis claims)", "",
                      f"{len(mine_own)} checks: {verdict_counts(mine_own)}.", ""]
            lines += _table(mine_own, OWN_KEYS, OWN_HEADINGS)
        for table in (r for r in mine if is_sensitivity(r)):
            lines += _sensitivity_md(table)
    side = [(r.get("chapter", "Claims"), as_claim(r)) for r in records
            if not is_sensitivity(r) and r.get("chapter") in SIDE_BY_SIDE]
    side = [(ch, c) for ch, c in side if c["kind"] == "thesis"]
    if side:
        lines += ["## Verdicts at the thesis's settings and at ours (chapters 3-5)", "",
                  "The thesis's model (printed plant and effort form) and r = 0.002, "
                  "w_v = 0.1, w_f = 0.01 against ours; chapter 5: its repertoire planned "
                  "with them, every row over the readings of eqs. 5.1/5.7 the thesis allows.",
                  "", _row(("chapter", "claim", "line", "ours", "at the thesis's settings")),
                  "|---|---|---|---|---|"]
        lines += [_row((ch, c["claim"], c["line"], c["verdict"],
                        at_thesis_verdict(c["at_thesis"], c["verdict"]))) for ch, c in side]
        lines.append("")
    return "\n".join(lines) + "\n"


#: Chapters whose verdicts the side-by-side table lists.
SIDE_BY_SIDE = ("Chapter 3", "Appendix A", "Chapter 4", "Chapter 5")


def run_chapter(
    title: str, module: str, out: Path, *, trials: int | None, seed: int, quick: bool,
    progress=None,
) -> tuple[list[dict], str | None, float | None, bool]:
    """Run one chapter into ``out``.

    Parameters
    ----------
    title : str
        The chapter's title in numbers.md.
    module : str
        Its module in tools/.
    out : Path
        Output folder.
    trials : int or None
        Repetitions everywhere (None: the thesis's counts).
    seed : int
        Base seed.
    quick : bool
        Smoke run (fewer observed movements in appendix A).
    progress : callable, optional
        Called with the name of each figure as it starts (chapters 2, 3, A).

    Returns
    -------
    records : list of dict
        Its claims and tables, each given ``chapter=title``.
    note : str or None
        Why it is missing or how it failed.
    seconds : float or None
        How long it took (None if it is missing).
    ok : bool
        False if it failed.
    """
    start = time.perf_counter()
    try:
        reproduce = load_chapter(module)
        if reproduce is None:
            if module not in OPTIONAL:
                raise ModuleNotFoundError(f"tools/{module}.py is missing")
            return [], (f"{title}: tools/{module}.py is missing, so its figures and claims "
                        "are not in this run."), None, True
        if module == "reproduce_ch4":  # its interface: (out, *, trials, seed)
            got = reproduce(out, trials=CH4_TRIALS if trials is None else trials, seed=seed)
        elif module == "reproduce_ch5":  # (out, *, clips, seed, progress): video, not trials
            got = reproduce(out, clips=CH5_CLIPS, seed=seed,
                            progress=progress or (lambda name: None))
        else:
            kwargs = {"repeats": 1} if quick and module == "reproduce_appendix_a" else {}
            got = reproduce(out, trials=trials, seed=seed,
                            progress=progress or (lambda name: None), **kwargs)
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
        missing/failed chapters; a timing line per chapter.
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
        timings += [f"{title}: {seconds:.1f} s"] if seconds is not None else []
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
    chapters = [c for c in CHAPTERS if not (args.skip_ch4 and c[1] == "reproduce_ch4")
                and not (skip_ch5 and c[1] == "reproduce_ch5")]
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
        f"Generated by `tools/reproduce_thesis.py` (seed {args.seed}; repetitions: "
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
        import evaluate_verdict

        _, result = evaluate_verdict.run("heldout", out / "verdict",
                                         evaluate_verdict.DEFAULT_COUNTS, jobs=args.jobs,
                                         quiet=True)
        text += "\n" + result["markdown"]
    write_text(out / "numbers.md", text)
    figures = sorted(p.name for p in out.glob("fig*.png"))
    thesis = [r for r in rows if r["kind"] == "thesis"]
    print(f"{len(figures)} figures, {_n_claims(thesis).replace('claims', 'thesis claims', 1)} "
          f"({claim_counts(thesis)}), "
          f"{len(rows) - len(thesis)} own checks in {out} "
          f"({total:.0f} s)")
    for n in notes:
        print(n)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
