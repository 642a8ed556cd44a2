"""The README and the docs: short, standing alone, and quoting only numbers that a make target
wrote (``docs/results/``), so that none can go stale."""

import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RESULTS = "docs/results/"
#: an include of pymdownx.snippets: --8<-- "path"
INCLUDE = re.compile(r'^--8<-- "([^"]+)"', re.M)
#: a path going up out of the folder it is written in (``.../`` in an elided path is not one)
UP = re.compile(r"(?<![.\w])\.\./")


def readme_module():
    spec = importlib.util.spec_from_file_location("readme", ROOT / "docs" / "readme.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def written_by_make():
    """The files under docs/results/ that a recipe of the Makefile writes (``$(RESULTS)/x``)."""
    makefile = (ROOT / "Makefile").read_text()
    recipes = "\n".join(line for line in makefile.splitlines() if line.startswith("\t"))
    return {RESULTS + name for name in re.findall(r"\$\(RESULTS\)/([\w.\-]+)", recipes)}


def doc_texts():
    """(path, text) of the README, the top-level Markdown files and every page and notebook
    under docs/."""
    paths = [ROOT / "README.md", ROOT / "ARCHITECTURE.md", ROOT / "CHANGELOG.md"]
    paths += sorted((ROOT / "docs").rglob("*.md")) + sorted((ROOT / "docs").rglob("*.ipynb"))
    return [(p.relative_to(ROOT).as_posix(), p.read_text()) for p in paths if p.exists()]


def test_the_readme_reads_in_five_minutes():
    assert (ROOT / "README.md").stat().st_size <= 10 * 1024


def test_nothing_points_outside_the_repository():
    sources = [(p.relative_to(ROOT).as_posix(), p.read_text())
               for folder in ("src", "benchmarks", "experiments", "conf", "docs")
               for p in sorted((ROOT / folder).rglob("*"))
               if p.suffix in (".py", ".yaml", ".c") and "__pycache__" not in p.parts]
    outside = [f"{path}: {line.strip()}" for path, text in doc_texts() + sources
               for line in text.splitlines() if UP.search(line)]
    assert not outside, "\n".join(outside)


def test_the_docs_cite_only_results_a_make_target_writes():
    written = written_by_make()
    assert written, "no recipe of the Makefile writes into docs/results/"
    cited = {(path, name) for path, text in doc_texts()
             for name in re.findall(r"docs/results/[\w.\-]+", text)}
    unwritten = sorted(f"{path} cites {name}" for path, name in cited if name not in written)
    assert not unwritten, "\n".join(unwritten)


def test_the_docs_include_only_files_that_exist():
    """An include is a results file a target writes, or a file of the repository outside
    outputs/ (ARCHITECTURE.md, CHANGELOG.md)."""
    written = written_by_make()
    for path, text in doc_texts():
        for name in INCLUDE.findall(text):
            assert (ROOT / name).is_file(), f"{path} includes {name}, which is not there"
            assert not name.startswith("outputs/"), f"{path} includes {name} from outputs/"
            if name.startswith(RESULTS):
                assert name in written, f"{path} includes {name}, which no target writes"


def test_every_results_file_is_written_by_a_target():
    written = written_by_make()
    present = {p.relative_to(ROOT).as_posix() for p in (ROOT / RESULTS).iterdir()}
    assert present <= written, f"not written by any make target: {sorted(present - written)}"


def test_the_readme_numbers_are_those_of_the_results():
    readme = readme_module()
    text = readme.README.read_text()
    names = re.findall(r"<!-- results: (\S+) -->", text)
    assert sorted(names) == sorted(readme.REGIONS)
    assert readme.rendered(text) == text, "README.md is stale: run `make readme`"


@pytest.mark.parametrize("text, count, passed", [
    ("| a | pass |\n| --- | --- |\n| x | pass |\n| y | FAIL |\n", 2, 1),
    ("| a | pass |\n| --- | --- |\n", 0, 0)])
def test_the_validation_headline_counts_rows(text, count, passed):
    line = readme_module().validation(text)
    assert f"compared {count} measurements" in line and f": {passed} within" in line


def test_every_make_target_the_docs_name_exists():
    makefile = (ROOT / "Makefile").read_text()
    targets = set(re.findall(r"^([a-z-]+):", makefile, re.M))
    named = {(path, target) for path, text in doc_texts()
             for target in re.findall(r"`make ([a-z-]+)", text)}
    missing = sorted(f"{path}: make {target}" for path, target in named if target not in targets)
    assert not missing, "\n".join(missing)


#: (page, code) of every Python block of the README and the getting-started page
PYTHON_EXAMPLES = [(name, code) for name in ("README.md", "docs/getting-started.md")
                   for code in re.findall(r"```python\n(.*?)```", (ROOT / name).read_text(), re.S)]


@pytest.mark.parametrize("page, code", PYTHON_EXAMPLES,
                         ids=[f"{name}-{k}" for k, (name, _) in enumerate(PYTHON_EXAMPLES)])
def test_the_python_examples_run(page, code, tmp_path):
    """Each example runs as printed; a run file it opens (``outputs/runs/DATE/TIME/run.h5``)
    is one the test makes, and its wall budget is widened so that a loaded machine cannot
    end the run before the stop the example claims."""
    from sim.pipeline.run_cache import compose_config
    from sim.pipeline.runner import run

    placeholder = "outputs/runs/DATE/TIME/run.h5"
    if placeholder in code:
        path = run(compose_config(["disks.n=200", "stop.collisions=2000",
                                   "output.progress=false"]), tmp_path)
        code = code.replace(placeholder, str(path))
    namespace = {}
    exec(compile(code.replace("wall_seconds=60", "wall_seconds=3600"), page, "exec"), namespace)
    claimed = re.search(r"reason = .*# -> \"(\w+)\"", code)
    if claimed:
        assert namespace["reason"] == claimed.group(1)


def test_every_page_the_code_and_docs_cite_exists():
    """A docstring, comment or page that names ``docs/<page>.md`` names a page there is."""
    texts = doc_texts() + [(p.relative_to(ROOT).as_posix(), p.read_text())
                           for folder in ("src", "tests", "benchmarks", "experiments")
                           for p in sorted((ROOT / folder).rglob("*.py"))]
    cited = {(path, page) for path, text in texts
             for page in re.findall(r"docs/[\w\-/]+\.md", text)}
    missing = sorted(f"{path}: {page}" for path, page in cited if not (ROOT / page).is_file())
    assert not missing, "\n".join(missing)
