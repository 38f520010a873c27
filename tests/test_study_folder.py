"""A study folder handed over whole (helper S, session 62): many kinds of file together through
``batch`` and ``landmarks``, a folder and a manifest. Every file here is written by the test
in the layouts of the public examples tried (a Qualisys TSV, notes beside them)."""

import numpy as np

from hammer_mv.cli import main


def _still_hand_tsv(path, n=200):
    """A Qualisys TSV export of a hand that never moves: read, but it gives no reach."""
    rng = np.random.default_rng(0)
    names = ["thumb", "index", "wrist"]
    at = {"thumb": (300.0, 0.0, 100.0), "index": (300.0, 40.0, 100.0),
          "wrist": (200.0, 20.0, 100.0)}
    rows = []
    for i in range(n):
        xyz = [f"{v + rng.normal(0, 0.05):.3f}" for m in names for v in at[m]]
        rows.append("\t".join([str(i + 1), f"{i / 100:.5f}", *xyz]))
    head = [f"NO_OF_FRAMES\t{n}", "NO_OF_CAMERAS\t7", "NO_OF_MARKERS\t3", "FREQUENCY\t100",
            "NO_OF_ANALOG\t0", "ANALOG_FREQUENCY\t0", "DESCRIPTION\t--",
            "TIME_STAMP\t2026-01-20, 10:25:12", "DATA_INCLUDED\t3D",
            "MARKER_NAMES\t" + "\t".join(names),
            "\t".join(["Frame", "Time", *(f"{m} {a}" for m in names for a in "XYZ")])]
    path.write_text("\r\n".join(head + rows) + "\r\n")


def test_landmarks_names_a_trial_not_scored_as_its_table_does(tmp_path, capsys):
    """``landmarks`` on a manifest said a trial not scored by its trial's name ('P01: not
    scored'), which neither the manifest nor the table's clip column holds (the clip
    'pilot'); batch says the clip. Now both say the clip."""
    _still_hand_tsv(tmp_path / "P01.tsv")
    (tmp_path / "manifest.csv").write_text("clip,video,participant\npilot,P01.tsv,P01\n")
    out = tmp_path / "out"
    out.mkdir()
    assert main(["landmarks", str(tmp_path / "manifest.csv"), "-o", str(out / "l.csv"),
                 "--quiet"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("pilot: not scored: "), err
    import pandas as pd

    table = pd.read_csv(out / "l.csv")
    assert set(table["clip"]) == {"pilot"}


def test_a_manifest_row_of_no_kind_says_every_kind_batch_reads(tmp_path, capsys):
    """A manifest row naming notes (not a clip) failed with load_clip's "not a video, tracks
    or pose file", although the batch reads motion-capture recordings too; the folder's
    own listing of the same file says all four. Now the row says them, and the batch goes
    on to the next row."""
    _still_hand_tsv(tmp_path / "P01.tsv")
    (tmp_path / "notes.txt").write_text("participant P01, right hand\n")
    (tmp_path / "manifest.csv").write_text(
        "clip,video,participant\nnotes,notes.txt,P01\npilot,P01.tsv,P01\n")
    out = tmp_path / "out"
    assert main(["batch", str(tmp_path / "manifest.csv"), "-o", str(out), "--quiet"]) == 1
    capsys.readouterr()
    import pandas as pd

    summary = pd.read_csv(out / "summary.csv").set_index("clip")
    assert set(summary.index) == {"notes", "pilot"}  # nothing lost: a row for each
    why = summary.loc["notes", "reason"]
    assert why.endswith("notes.txt: not a video, tracks file, pose file or motion-capture "
                        "recording"), why
    assert summary.loc["pilot", "status"] != "failed"  # the batch went on past the bad row


def test_a_c3d_description_over_127_characters_is_refused_before_ezc3d(tmp_path):
    """c3d.org's BKINtechnologies.c3d (a description of 163 characters) and
    bad_parameter_section.c3d (a length byte of 211 where an offset is wrong): ezc3d reads
    the byte as signed and asked for about 4 GB (12.4 GB held by the batch that read one;
    a batch and a landmarks run at once were killed for memory). Refused first, naming
    the parameter; a file of short descriptions is read as before."""
    import pytest

    ezc3d = pytest.importorskip("ezc3d", reason="the 'mocap' extra")
    from perception.errors import InputError
    from perception.io.mocap import read_mocap

    path = tmp_path / "kinarm.c3d"
    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [100]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = ("thumb", "index")
    c3d["data"]["points"] = np.ones((4, 2, 10))
    c3d.write(str(path))
    data = bytearray(path.read_bytes())
    start = (data[0] - 1) * 512
    at = data.index(b"POINT", start)  # the POINT group: its offset (2 bytes), its description
    assert data[at + 7] < 128  # as ezc3d writes it
    assert len(read_mocap(path)) == 1
    data[at + 7] = 164  # as BKIN's EXPERIMENT:SESSION, 0xA4: -92 to ezc3d
    path.write_bytes(bytes(data))
    with pytest.raises(InputError, match="the description of POINT is 164 characters long") as e:
        read_mocap(path)
    assert "not a readable C3D file" in str(e.value) and "kinarm.c3d" in str(e.value)
