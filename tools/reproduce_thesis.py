"""Regenerate the thesis's figures and a table of its quantitative claims beside ours.

    python tools/reproduce_thesis.py [-o out/thesis] [--trials N] [--seed N] [--quick]

Writes, into the output folder, every figure of chapter 2 (2.5-2.8), chapter 3
(3.2-3.9) and appendix A (A.1-A.3) as PNG named after the thesis figure
(``fig3_5_speed_accuracy.png``), CSV tables beside the figures that have
numbers, the chapter 4 figures when ``tools/reproduce_ch4.py`` exists, chapter 5
from rendered video in ``ch5/`` (``tools/reproduce_ch5.py``; not with
``--quick``), and
``numbers.md``: one row per quantitative claim of the thesis with our value,
whether it agrees, and why not where it does not. Every file is written to a
temporary name and renamed when complete.

``--trials`` sets the Monte Carlo repetitions everywhere (default: the
thesis's counts, 500 per setting in chapter 4); ``--quick`` is a smoke run
(10 repetitions, one observed movement per test trajectory in Fig. A.1).
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
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for _p in (ROOT, ROOT / "tools"):
    if str(_p) not in sys.path:
        sys.path.insert(0, str(_p))

import pandas as pd  # noqa: E402
from reproduce_common import CLAIM_KEYS  # noqa: E402
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
    if isinstance(value, bool):
        return "yes" if value else "**no**"
    return str(value).replace("|", "\\|").replace("\n", " ")


def numbers_markdown(claims: list[dict], notes: list[str], header: list[str]) -> str:
    """numbers.md: a header, run notes, and one table row per claim.

    Parameters
    ----------
    claims : list of dict
        Rows with keys section, claim, thesis, ours, agrees, note.
    notes : list of str
        Lines about the run (missing or failed chapters), shown above the table.
    header : list of str
        Lines describing the run (options, timings).
    """
    for c in claims:
        missing = [k for k in CLAIM_KEYS if k not in c]
        if missing:
            raise ValueError(f"claim {c!r} lacks {missing}")
    agree = sum(bool(c["agrees"]) for c in claims)
    lines = ["# Thesis claims beside ours", "", *header, ""]
    lines += [f"- {n}" for n in notes]
    lines += [f"- {agree} of {len(claims)} claims agree.", ""]
    lines.append("| " + " | ".join(CLAIM_KEYS) + " |")
    lines.append("|" + "---|" * len(CLAIM_KEYS))
    for c in claims:
        lines.append("| " + " | ".join(_cell(c[k]) for k in CLAIM_KEYS) + " |")
    return "\n".join(lines) + "\n"


def run(
    out: Path, *, trials: int | None, seed: int, quick: bool, chapters=CHAPTERS
) -> tuple[list[dict], list[str], list[str], bool]:
    """Run every chapter into ``out``.

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

    Returns
    -------
    claims, notes, timings : lists
        All claims; notes on missing/failed chapters; a timing line per chapter.
    ok : bool
        False if a chapter failed.
    """
    if quick and trials is None:
        trials = QUICK_TRIALS
    ok, claims, notes, timings = True, [], [], []
    bar = tqdm(chapters, unit="chapter", disable=not sys.stderr.isatty())
    for title, module in bar:
        bar.set_description(title)
        start = time.perf_counter()
        try:
            reproduce = load_chapter(module)
            if reproduce is None:
                if module not in OPTIONAL:
                    raise ModuleNotFoundError(f"tools/{module}.py is missing")
                notes.append(f"{title}: tools/{module}.py is missing, so its figures and "
                             "claims are not in this run.")
                start = None
                continue
            if module == "reproduce_ch4":  # another engineer's interface: (out, *, trials, seed)
                got = reproduce(out, trials=CH4_TRIALS if trials is None else trials, seed=seed)
            elif module == "reproduce_ch5":  # (out, *, clips, seed, progress): video, not trials
                got = reproduce(out, clips=CH5_CLIPS, seed=seed,
                                progress=lambda name: bar.set_postfix_str(name))
            else:
                kwargs = {"repeats": 1} if quick and module == "reproduce_appendix_a" else {}
                got = reproduce(out, trials=trials, seed=seed,
                                progress=lambda name: bar.set_postfix_str(name), **kwargs)
            claims += list(got)
        except Exception as exc:  # report and go on with the other chapters
            ok = False
            log.exception("%s failed", title)
            notes.append(f"{title} FAILED: {type(exc).__name__}: {exc}")
        finally:
            if start is not None:
                timings.append(f"{title}: {time.perf_counter() - start:.1f} s")
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
    args = parser.parse_args(argv)
    if args.trials is not None and args.trials < 2:
        parser.error("--trials must be at least 2 (standard deviations need two)")
    logging.basicConfig(level=logging.WARNING, format="%(name)s: %(message)s")

    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    skip_ch5 = args.skip_ch5 or args.quick
    chapters = [c for c in CHAPTERS if not (args.skip_ch4 and c[1] == "reproduce_ch4")
                and not (skip_ch5 and c[1] == "reproduce_ch5")]
    start = time.perf_counter()
    claims, notes, timings, ok = run(
        out, trials=args.trials, seed=args.seed, quick=args.quick, chapters=chapters
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
        + f"); {total:.0f} s in all ({'; '.join(timings)}).",
        "Each claim names how agreement was judged; where ours differs the note says why. "
        "Figures and CSV tables are beside this file.",
    ]
    write_csv(out / "numbers.csv", pd.DataFrame(claims, columns=list(CLAIM_KEYS)))
    write_text(out / "numbers.md", numbers_markdown(claims, notes, header))
    figures = sorted(p.name for p in out.glob("fig*.png"))
    print(f"{len(figures)} figures, {len(claims)} claims "
          f"({sum(bool(c['agrees']) for c in claims)} agree) in {out} ({total:.0f} s)")
    for n in notes:
        print(n)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
