"""README's Python examples run as written, in order, in one namespace."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def _python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)


def test_readme_python_blocks_run(tmp_path, monkeypatch):
    blocks = _python_blocks()
    assert len(blocks) >= 3
    monkeypatch.chdir(tmp_path)  # any file an example writes lands here
    namespace: dict = {}
    for i, block in enumerate(blocks):
        try:
            exec(compile(block, f"README.md python block {i + 1}", "exec"), namespace)
        except Exception as exc:  # pragma: no cover - the message is the point
            raise AssertionError(f"README python block {i + 1} fails: {exc!r}\n{block}") from exc
    # the examples compute what they say
    assert namespace["rec"].winner.startswith("grasp-")
    assert namespace["peak_to_mean_ratio"](3) == 1.875


def test_readme_names_the_default_repertoire_size_and_every_clip_figure():
    from perception.recognition.planning import default_specs
    from perception.report.clip import clip_outputs

    text = README.read_text()
    said = re.search(r"repertoire build -o rep\.h5 +# plan the models once \((\d+) by default\)",
                     text)
    assert said and int(said.group(1)) == len(default_specs())
    # what recognize writes for one clip: every file a user finds there is named
    figures = [p.name for k, p in clip_outputs(Path("out"), "<clip>").items()
               if p.suffix == ".png"]
    assert len(figures) >= 3
    for name in figures:
        assert f"`{name}`" in text, name


def test_solver_defaults_in_the_docs_are_the_functions_own():
    # README once said tol=1e-12 where the default is 0 (Todorov's absolute test
    # alone): a modeller copying it would stop at another iteration than his code
    import inspect

    import minvar

    defaults = {name: p.default for name, p in inspect.signature(minvar.solve).parameters.items()
                if p.default is not inspect.Parameter.empty}
    for doc in (README, README.parent / "docs" / "model.md"):
        said = re.findall(r"`minvar\.solve\(problem, ([^`]*)\)`", doc.read_text())
        assert said, doc.name
        for args in said:
            for name, value in (a.split("=") for a in args.split(", ")):
                assert float(value) == defaults[name], (doc.name, name, value)
