"""MkDocs hooks: the pages made from the code and from what the make targets wrote.

- ``configuration.md``: every scene and config key, from the schema and the comments of
  ``conf/config.yaml`` (:func:`sim.pipeline.config_reference.markdown`, the text of ``--help``).
- ``figures.md``: the gallery, one section per figure stage of :mod:`sim.figures` (its
  docstring), with the web image and the numbers that ``make figures`` wrote into
  ``docs/results/figures/`` (:mod:`sim.figures.web`), or else the ``QUICK=1`` versions of
  ``outputs/figures/quick/``.
- ``results/speed.png``: the figure of the speed table that ``performance.md`` shows, put into
  the site; the rest of ``docs/results/`` is left out of it, its text included into pages.
- ``api/engine.md``: the table of the effects' Engine keywords (each effect module's
  ``KEYWORDS``), which the Engine's docstring gains only when the module is imported.
- ``faults-and-clusters.md``: what each job of a sweep on SLURM asks for by default
  (:func:`sim.pipeline.cluster.resource_table`, from the module's constants).
- every page: the Sphinx roles of the docstrings (``:class:`Engine` ``) shown as the name.
"""

import csv
import importlib
import io
import re
import sys
import textwrap
from pathlib import Path

from mkdocs.structure.files import File, InclusionLevel

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

FIGURES = ROOT / "outputs" / "figures"
#: the web versions that ``make figures`` writes and the repository keeps (sim.figures.web)
PUBLISHED = ROOT / "docs" / "results" / "figures"
#: where api/engine.md shows the effects' keywords
EFFECT_KEYWORDS = "<!-- effect keywords -->"
#: where faults-and-clusters.md shows what a job on a cluster asks for (sim.pipeline.cluster)
CLUSTER_RESOURCES = re.compile(r"^( *)<!-- cluster resources -->", re.M)
#: number files at most this large are shown as tables in the gallery (bytes)
LARGEST_TABLE = 4000
#: the images of docs/results/ that pages show, published although results/ is excluded
SHOWN_RESULTS = ["results/speed.png"]
#: a Sphinx cross-reference in a docstring, ``:func:`name` ``, shown as code
ROLE = re.compile(r":[a-z]+:`~?([^`]+)`")
#: the same, as the API reference renders it: the role left before the code
RENDERED_ROLE = re.compile(r":(?:class|func|meth|mod|data|attr|exc|obj):(<code>)~?")


def on_files(files, config):
    from sim.pipeline.config_reference import markdown

    files.append(File.generated(config, "configuration.md", content=markdown()))
    page, images = gallery()
    files.append(File.generated(config, "figures.md", content=page))
    for name, path in images:
        files.append(File.generated(config, f"figures/{name}", abs_src_path=str(path)))
    for name in SHOWN_RESULTS:
        shown = files.get_file_from_path(name)
        if shown is None:
            raise FileNotFoundError(f"docs/{name} is missing: make speed draws it")
        shown.inclusion = InclusionLevel.INCLUDED
    return files


def on_page_markdown(markdown, page, config, files):
    """The effects' keywords where ``api/engine.md`` asks for them, and what a job on a
    SLURM cluster asks for by default where ``faults-and-clusters.md`` does (at the
    indentation of the marker)."""
    from sim.pipeline.cluster import resource_table

    markdown = markdown.replace(EFFECT_KEYWORDS, effect_keywords())
    return CLUSTER_RESOURCES.sub(
        lambda found: textwrap.indent(resource_table(), found.group(1)), markdown)


def effect_keywords():
    """Every effect's Engine keywords: keyword, default, meaning, and the effect's module."""
    from sim.effects import EFFECTS

    rows = ["| keyword | default | meaning | effect |", "| --- | --- | --- | --- |"]
    for effect in EFFECTS:
        name = effect.module.__name__
        for keyword, (default, meaning) in effect.module.KEYWORDS.items():
            cell = ROLE.sub(r"`\1`", meaning).replace("|", "\\|")
            rows.append(f"| `{keyword}` | `{default!r}` | {cell} | `{name}` |")
    return "\n".join(rows)


def on_page_content(html, page, config, files):
    """Docstrings write cross-references as Sphinx roles; the page shows the name alone."""
    return RENDERED_ROLE.sub(r"\1", html)


def gallery():
    """The gallery page and the images it shows, as (site name, file) pairs."""
    from sim.figures import STAGES

    lines = [(ROOT / "docs" / "gallery-intro.md").read_text()]
    images = []
    for stage_name in STAGES:
        stage = importlib.import_module(f"sim.figures.{stage_name}")
        text = ROLE.sub(r"`\1`", stage.__doc__.strip())
        title = heading(text)
        lines += [f"## {title}", "", text, ""]
        folder = next((f for f in (PUBLISHED, FIGURES / "quick")
                       if (f / f"{stage.NAME}.png").exists()), None)
        if folder is None:
            if stage_name != "movies":
                lines += ["*Not made yet here: `make figures` (or `make figures QUICK=1`).*", ""]
            continue
        quick = " (quick version)" if folder.name == "quick" else ""
        images.append((f"{stage.NAME}.png", folder / f"{stage.NAME}.png"))
        lines += [f"![{title}{quick}](figures/{stage.NAME}.png)", ""]
        for numbers in sorted(folder.glob(f"{stage.NAME}*.txt")) + sorted(
                folder.glob(f"{stage.NAME}*.csv")):
            if numbers.stat().st_size <= LARGEST_TABLE:
                lines += [f"`{numbers.name}`{quick}:", "", as_markdown(numbers), ""]
    return "\n".join(lines), images


def heading(docstring):
    """A stage's heading: the first sentence of its docstring, or, when that is long, its
    part before the first parenthesis or second colon ("Figure 9: crater area against …")."""
    sentence = " ".join(re.split(r"\.\s", docstring, maxsplit=1)[0].split())
    if len(sentence) > 90:
        sentence = ":".join(sentence.split(" (")[0].split(":")[:2])
    return sentence.rstrip(".")


def number(cell):
    """A CSV cell as written, or to six significant digits when it is a float."""
    try:
        return f"{float(cell):.6g}" if any(c in cell for c in ".eE") else cell
    except ValueError:
        return cell


def as_markdown(path):
    """A CSV file as a Markdown table; a text file as a code block."""
    text = path.read_text()
    if path.suffix != ".csv":
        return f"```\n{text.rstrip()}\n```"
    rows = list(csv.reader(io.StringIO(text)))
    table = ["| " + " | ".join(rows[0]) + " |", "|" + " --- |" * len(rows[0])]
    table += ["| " + " | ".join(number(cell) for cell in row) + " |" for row in rows[1:]]
    return "\n".join(table)
