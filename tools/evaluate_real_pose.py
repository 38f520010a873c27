"""Real motion-capture grasps written as DeepLabCut files: does the pose path see the same?

The same movement must give the same landmarks and verdict whichever file it
comes in (issue 41, "one cleaning for every source"). This check takes a
recording of real grasps (a lab's table with a trial column, read as
:func:`tools.evaluate_real` reads it), writes each reach's *raw* samples as a
2D DeepLabCut table, as a camera beside the movement would see them with a
tracker that made the recording's own errors, and scores that file through
the pose path (``load_clip`` → ``recognize_tracks``, what ``hammer-mv
recognize FILE.csv`` does):

* the view (:func:`pose_tracks`): the movement's plane, the digits across
  the approach at their 3D aperture, as the motion-capture path brings a
  reach into its plane (:func:`perception.reaches.reach_tracks`);
  :data:`PX_PER_M` pixels per metre, image y down;
* the errors: over the reach's own rows of the raw trial, each digit's
  error (raw minus cleaned marker, projected into the plane) is added to
  its image, a sample the recording repeats exactly is repeated in the
  image (a keypoint frozen where it was last seen), a lost one is empty
  (likelihood 0): the spikes, held samples and gaps the recording has,
  uncleaned. The wrist, which the recording lacks, is the grip 6 cm back
  along the approach, tracked well (``--wrist clean``) or with the thumb
  marker's errors (``--wrist thumb``); the object at the hand's end;
* beside it, the same camera on the cleaned 3D reach (``<reach>.clean.csv``):
  what the file would hold without the recording's errors.

For each reach it reports the pose file's verdict and landmarks beside the
field's definitions (``independent_landmarks`` of ``tools/evaluate_real.py``,
on the cleaned 3D reach) and the motion-capture path's peak speed::

    python tools/evaluate_real_pose.py TRIALS.tsv --rate 85 \\
        --markers thumb=thumb finger=index --set heldout -o out/eval-pose

Writes ``OUT/evaluation.md``, ``OUT/evaluation.json`` and the DeepLabCut
files under ``OUT/dlc/``, and prints the table.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time as _time
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from evaluate_real import independent_landmarks  # noqa: E402

from perception.errors import HammerMVError  # noqa: E402
from perception.io.atomic import write_text  # noqa: E402
from perception.io.exports import write_dlc  # noqa: E402
from perception.io.mocap import read_mocap  # noqa: E402
from perception.io.pose import PoseImport  # noqa: E402
from perception.io.tracks import Status, Tracks  # noqa: E402
from perception.observation import ObserveParams  # noqa: E402
from perception.reaches import MarkerMap, ReachParams, fit_plane  # noqa: E402
from perception.recognition.repertoire import Repertoire  # noqa: E402
from perception.recordings import MocapImport, read_reaches, recognize_reach  # noqa: E402

#: The camera's scale: pixels per metre (a 1080p camera seeing about 1.3 m).
PX_PER_M = 800.0
_ORIGIN_PX = np.array([900.0, 700.0])


def raw_rows(reach, trials: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The raw trial's time, finger and thumb over the reach's rows (m, uncleaned)."""
    trial_name = reach.name.rsplit("-reach", 1)[0] if reach.name not in trials else reach.name
    trial = trials[trial_name]
    a = int(np.searchsorted(trial.time, reach.time[0] - 1e-9))
    rows = slice(a, a + len(reach.time))
    return trial.time[rows], trial.markers["finger"][rows], trial.markers["thumb"][rows]


def _filled(time: np.ndarray, path: np.ndarray) -> np.ndarray:
    """A path with its lost samples filled linearly (the construction's stand-in truth)."""
    ok = np.isfinite(path).all(axis=1)
    return np.stack([np.interp(time, time[ok], path[ok, k]) for k in range(path.shape[1])],
                    axis=1)


def pose_tracks(reach, finger: np.ndarray, thumb: np.ndarray, time: np.ndarray,
                px_per_m: float = PX_PER_M, wrist: str = "clean") -> tuple[Tracks, float]:
    """The reach as a camera's tracks (px) carrying the given markers' errors, and the
    object's size (m).

    The camera sees the movement's plane (:func:`fit_plane` of the cleaned
    transport) with the digits across the approach at their 3D aperture, as
    :func:`perception.reaches.reach_tracks` brings a reach into its plane.
    Each digit's error in ``finger`` and ``thumb`` (their difference from
    the cleaned markers, projected into the plane) is added to its image; a
    sample that repeats the previous one exactly repeats it in the image too
    (a keypoint frozen where it was last seen); a lost one is lost. Given the
    cleaned markers, the file holds the motion-capture path's own tracks.

    The wrist, which the recording lacks, is the grip `ReachParams.wrist_behind`
    back along the approach: without errors (``wrist`` ``"clean"``: a
    keypoint tracked well) or with the thumb's (``"thumb"``). The object
    sits at the origin.
    """
    seen = np.flatnonzero(np.isfinite(reach.transport[:reach.end + 1]).all(axis=1))
    origin = reach.object if reach.object is not None else reach.transport[seen[-1]]
    plane = fit_plane(reach, origin)
    t = reach.time
    true_f, true_t = _filled(t, reach.finger), _filled(t, reach.thumb)
    g = np.linalg.norm(true_f - true_t, axis=1)
    rest = np.nanmedian(g[max(0, reach.onset - 5):reach.onset + 1])
    size = max(float(np.nanmedian(g[max(0, reach.end - 2):reach.end + 1]) - rest), 0.005)
    mid = plane.project(0.5 * (true_f + true_t))
    across = np.array([1.0, 0.0])
    true2d = {"finger": mid + 0.5 * g[:, None] * across, "thumb": mid - 0.5 * g[:, None] * across}
    back = mid - np.array([0.0, ReachParams().wrist_behind])

    def seen_as(name, given, truth, image):
        err = plane.project(given) - plane.project(truth)  # the marker's error, in the plane
        out = image + err
        same = np.r_[False, (np.diff(given, axis=0) == 0).all(axis=1)]
        for k in np.flatnonzero(same):
            out[k] = out[k - 1]
        return out

    f2 = seen_as("finger", finger, true_f, true2d["finger"])
    t2 = seen_as("thumb", thumb, true_t, true2d["thumb"])
    w2 = seen_as("wrist", thumb, true_t, back) if wrist == "thumb" else back
    pos = np.stack([t2, f2, w2, np.zeros_like(mid)], axis=1)
    px = _ORIGIN_PX + px_per_m * pos * np.array([1.0, -1.0])
    lost = ~np.isfinite(px).all(axis=-1)
    px[lost] = np.nan
    tracks = Tracks(frame=np.arange(len(time)), time=time - time[0],
                    markers=("thumb", "finger", "wrist", "object"), position=px,
                    likelihood=np.where(lost, 0.0, 1.0).astype(np.float32),
                    status=np.where(lost, Status.LOST, Status.TRACKED).astype(np.int8))
    return tracks, size


def _speed_peak(reach) -> float:
    """The field's peak transport speed, m/s (10 Hz zero-lag filter, 3D grip midpoint)."""
    from scipy.signal import butter, filtfilt

    t = reach.time
    mid = 0.5 * (reach.finger + reach.thumb)
    ok = np.isfinite(mid).all(axis=1)
    mid = np.stack([np.interp(t, t[ok], mid[ok, k]) for k in range(3)], axis=1)
    b, a = butter(2, 10 / (0.5 / np.median(np.diff(t))))
    v = np.linalg.norm(np.gradient(filtfilt(b, a, mid, axis=0), t, axis=0), axis=1)
    return float(v.max())


def evaluate(path: Path, options: MocapImport, which: str, out: Path,
             px_per_m: float = PX_PER_M, mocap: bool = True, wrist: str = "clean") -> dict:
    """Score the chosen reaches as DeepLabCut files (and, with ``mocap``, as the table)."""
    reaches = read_reaches(path, options)
    raw = read_mocap(path, rate=options.rate, units=options.units,
                     trial_column=options.trial_column)
    markers = options.markers or MarkerMap()
    trials = {t.name: t.__class__(t.name, t.source, t.time,
                                  {"finger": t.markers[markers.finger],
                                   "thumb": t.markers[markers.thumb]}, t.rate, t.units)
              for t in raw}
    chosen = {"dev": reaches[0::2], "heldout": reaches[1::2], "all": reaches}[which]
    rep = Repertoire.default()
    folder = out / "dlc"
    folder.mkdir(parents=True, exist_ok=True)
    rows = []
    for reach in chosen:
        time, finger, thumb = raw_rows(reach, trials)
        mt_truth, _ = independent_landmarks(reach)
        row = {"trial": reach.name, "mt_truth": mt_truth, "peak_truth": _speed_peak(reach)}
        # the recording's own errors, and the same camera on the cleaned 3D reach
        for key, (f, t) in (("", (finger, thumb)), ("clean_", (reach.finger, reach.thumb))):
            tracks, size = pose_tracks(reach, f, t, time, px_per_m, wrist)
            dlc = write_dlc(tracks, folder / f"{reach.name}{'.clean' if key else ''}.csv")
            row.update(_score(dlc, reach.name, size, px_per_m, 1 / np.median(np.diff(time)),
                              rep, key))
        if mocap:
            try:
                mrec, _ = recognize_reach(reach, rep, None, options)
                mlm = mrec.landmarks[0]
                row.update(mocap_verdict=mrec.verdict, mocap_mt=mlm.movement_time,
                           mocap_peak=mlm.peak_speed, mocap_mga=mlm.mga)
            except (HammerMVError, ValueError) as exc:
                row.update(mocap_verdict="refused", mocap_reason=str(exc))
        rows.append(row)
    return summarise(rows, which, path)


def _score(dlc: Path, name: str, size: float, px_per_m: float, fps: float, rep,
           key: str) -> dict:
    """One DeepLabCut file scored as ``hammer-mv recognize`` scores it (keys prefixed)."""
    from perception.pipeline import RecognitionSettings, load_clip, recognize_tracks

    if "cleaning" in PoseImport.__dataclass_fields__:
        from perception.track_cleaning import TrackCleaning

        # the recognition's scale given to the cleaning too (the CLI passes --px-per-m)
        pose = PoseImport(fps=float(fps), cleaning=TrackCleaning(px_per_m=px_per_m))
    else:  # a version before pose files were cleaned: measured as it was
        pose = PoseImport(fps=float(fps))
    settings = RecognitionSettings(observe=ObserveParams(px_per_m=px_per_m,
                                                         object_diameter=size), pose=pose)
    try:
        rec = recognize_tracks(load_clip(dlc, pose=settings.pose), rep, settings, clip=name,
                               source=dlc)
        lm = rec.landmarks[0]
        out = {"verdict": rec.verdict, "detail": rec.verdict_detail, "mt": lm.movement_time,
               "peak": lm.peak_speed, "mga": lm.mga,
               "notes": list(getattr(rec.observation, "notes", ()) or ())}
    except (HammerMVError, ValueError) as exc:
        out = {"verdict": "refused", "detail": None, "mt": math.nan, "peak": math.nan,
               "mga": math.nan, "reason": str(exc)}
    return {key + k: v for k, v in out.items()}


def _median(values) -> float:
    values = [v for v in values if math.isfinite(v)]
    return float(np.median(values)) if values else math.nan


def summarise(rows: list[dict], which: str, path: Path) -> dict:
    """Counts and medians of the rows (what the issue's targets read)."""
    verdicts = Counter(f"{r['verdict']}" + (f" ({r['detail']})" if r.get("detail") else "")
                       for r in rows)
    mt_err = [r["mt"] - r["mt_truth"] for r in rows]
    peak_ratio = [r["peak"] / r["peak_truth"] - 1 for r in rows]
    out = {"set": which, "input": path.name, "reaches": len(rows),
           "normal": sum(r["verdict"] == "normal" for r in rows), "verdicts": dict(verdicts),
           "movement_time_median_abs_error_s": _median(np.abs(mt_err)),
           "movement_time_mean_error_s": float(np.nanmean(mt_err)) if rows else math.nan,
           "peak_speed_median_excess": _median(peak_ratio),
           "peak_speed_mean_excess": float(np.nanmean(peak_ratio)) if rows else math.nan,
           "rows": rows}
    out["clean_normal"] = sum(r["clean_verdict"] == "normal" for r in rows)
    out["same_verdict_as_clean"] = sum(r["clean_verdict"] == r["verdict"] for r in rows)
    out["clean_movement_time_median_abs_error_s"] = _median(
        np.abs([r["clean_mt"] - r["mt_truth"] for r in rows]))
    out["movement_time_median_abs_diff_clean_s"] = _median(
        np.abs([r["mt"] - r["clean_mt"] for r in rows]))
    out["peak_speed_median_excess_over_clean"] = _median(
        [r["peak"] / r["clean_peak"] - 1 for r in rows])
    out["peak_speed_mean_excess_over_clean"] = float(np.nanmean(
        [r["peak"] / r["clean_peak"] - 1 for r in rows])) if rows else math.nan
    if rows and "mocap_verdict" in rows[0]:
        same = [r for r in rows if r["verdict"] == r.get("mocap_verdict")]
        out["same_verdict_as_mocap"] = len(same)
        out["mocap_normal"] = sum(r.get("mocap_verdict") == "normal" for r in rows)
        out["movement_time_median_abs_diff_mocap_s"] = _median(
            [abs(r["mt"] - r.get("mocap_mt", math.nan)) for r in rows])
        out["peak_speed_median_excess_over_mocap"] = _median(
            [r["peak"] / r.get("mocap_peak", math.nan) - 1 for r in rows])
    return out


def markdown(res: dict) -> str:
    lines = [f"## `{res['input']}` as DeepLabCut files, {res['set']} reaches ({res['reaches']}), "
             f"wrist {res.get('wrist', 'clean')}",
             "", f"- `normal`: {res['normal']} / {res['reaches']} "
                 f"({', '.join(f'{k} {v}' for k, v in sorted(res['verdicts'].items()))})",
             f"- movement time against the field's definition: median |error| "
             f"{res['movement_time_median_abs_error_s'] * 1000:.0f} ms, mean error "
             f"{res['movement_time_mean_error_s'] * 1000:+.0f} ms",
             f"- peak speed against the field's: median {res['peak_speed_median_excess']:+.1%}, "
             f"mean {res['peak_speed_mean_excess']:+.1%}"]
    lines += [f"- the same camera on the cleaned 3D reach: `normal` {res['clean_normal']} / "
              f"{res['reaches']}, movement time median |error| "
              f"{res['clean_movement_time_median_abs_error_s'] * 1000:.0f} ms; the file with the "
              f"recording's errors gives its verdict {res['same_verdict_as_clean']} / "
              f"{res['reaches']} times, movement time median |difference| "
              f"{res['movement_time_median_abs_diff_clean_s'] * 1000:.0f} ms, peak speed median "
              f"{res['peak_speed_median_excess_over_clean']:+.1%} (mean "
              f"{res['peak_speed_mean_excess_over_clean']:+.1%})"]
    if "same_verdict_as_mocap" in res:
        lines += [f"- the table read directly: `normal` {res['mocap_normal']} / {res['reaches']};"
                  f" same verdict as the pose file {res['same_verdict_as_mocap']} / "
                  f"{res['reaches']}; movement time median |difference| "
                  f"{res['movement_time_median_abs_diff_mocap_s'] * 1000:.0f} ms; peak speed "
                  f"median {res['peak_speed_median_excess_over_mocap']:+.1%}"]
    for r in res["rows"]:
        if r["verdict"] != "normal":
            lines.append(f"  - {r['trial']}: {r['verdict']} {r.get('detail') or ''} "
                         f"{r.get('reason', '')}".rstrip())
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("input", type=Path)
    p.add_argument("--rate", type=float, default=None)
    p.add_argument("--markers", nargs="+", default=None, metavar="ROLE=NAME")
    p.add_argument("--set", choices=("dev", "heldout", "all"), default="heldout")
    p.add_argument("--px-per-m", type=float, default=PX_PER_M)
    p.add_argument("--wrist", choices=("clean", "thumb"), default="clean",
                   help="the wrist keypoint: the cleaned grip 6 cm back (clean), or the raw "
                        "thumb marker moved there, with its errors (thumb)")
    p.add_argument("--no-mocap", action="store_true",
                   help="do not also score the table itself (faster)")
    p.add_argument("-o", "--output", type=Path, required=True)
    args = p.parse_args(argv)
    from hammer_mv.cli.options import mocap_import

    args.units = args.trial_column = args.object_size = None
    options = mocap_import(args)
    if options.markers is None:
        options = MocapImport(markers=MarkerMap("thumb", "index"), rate=args.rate)
    start = _time.perf_counter()
    res = evaluate(args.input, options, args.set, args.output, args.px_per_m,
                   mocap=not args.no_mocap, wrist=args.wrist)
    res["wrist"] = args.wrist
    res["seconds"] = round(_time.perf_counter() - start, 1)
    md = markdown(res) + f"\n{res['reaches']} reaches scored in {res['seconds']} s.\n"
    write_text(args.output / "evaluation.md", md)
    write_text(args.output / "evaluation.json", json.dumps(res, indent=1, default=str) + "\n")
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
