"""The reference of every scenario and key (sim.pipeline.config_reference) cannot drift: every
key of the schema has its comment in conf/ and every commented key is in the schema; the
Markdown page and ``python -m sim --help`` name every key and every scenario, and the help
loads neither numba nor Hydra, which keeps ``--hydra-help``."""

import re
import subprocess
import sys

import pytest

import sim.__main__
from sim.pipeline import config_reference
from sim.pipeline.config_reference import (
    CONF,
    NOT_KEYS,
    comments,
    markdown,
    reference,
    scene_comments,
    scene_sections,
    schema_keys,
    text,
)

SCHEMA = set(schema_keys())
SCENARIOS = sorted(path.stem for path in (CONF / "scenario").glob("*.yaml"))
#: what Hydra's own --help prints
HYDRA_HELP = ("powered by Hydra", "== Configuration groups ==", "== Config ==",
              "Override anything in the config")


def _expanded(name):
    """The keys of a rendered name: ``walls.left|right.speed`` → both walls' keys."""
    head, _, leaf = name.rpartition(".")
    parent, _, middle = head.rpartition(".")
    return {f"{parent}.{m}.{leaf}" for m in middle.split("|")} if "|" in middle else {name}


def _prefixes(key):
    parts = key.split(".")
    return {".".join(parts[:i]) for i in range(1, len(parts) + 1)}


def test_every_schema_key_has_its_comment_and_every_comment_its_key():
    _, said = comments((CONF / "config.yaml").read_text())
    said = {k: c for k, c in said.items() if k.split(".")[0] not in NOT_KEYS}
    sections = scene_sections()
    from_scenes = scene_comments(reference().scenarios, sections)
    paths = {p for key in SCHEMA for p in _prefixes(key)}
    assert set(said) | set(from_scenes) <= paths, "commented keys outside the schema: " \
        f"{sorted((set(said) | set(from_scenes)) - paths)}"
    uncommented = {key for key in SCHEMA if key not in said and key not in from_scenes}
    assert not uncommented, f"keys of the schema without a comment in conf/: {uncommented}"
    assert not any(key.split(".")[0] in sections for key in said)


def test_every_key_has_its_row_with_a_meaning():
    keys = [k for section in reference().sections for k in section.keys]
    assert sorted(key for k in keys for key in k.keys) == sorted(SCHEMA)
    assert all(k.meaning and k.kind and k.default for k in keys)
    walls = [k for k in keys if k.keys[0].startswith("walls.")]
    assert {k.name for k in walls} == {f"walls.left|right|bottom|top.{leaf}"
                                       for leaf in ("temperature", "speed", "amplitude",
                                                    "frequency")}


def test_comments_follow_the_yaml_structure():
    """Continuation lines right of the colon, a comment line introducing the key below, a
    section's comment, a one-line section taking its sibling's comments, a quoted #."""
    said = comments(
        "# header\n"
        "a:            # section a\n"
        "  b: 1        # b's meaning,\n"
        "              # continued\n"
        "  # c's meaning\n"
        "  c: 'x # y'\n"
        "  d:\n"
        "    e: 0      # e\n"
        "  f: {e: 1}\n")
    assert said == (["header"], {"a": "section a", "a.b": "b's meaning, continued",
                                 "a.c": "c's meaning", "a.d.e": "e", "a.f.e": "e"})
    with pytest.raises(ValueError, match="not a key"):
        comments("a: 1\nnot a key\n")


def test_the_markdown_page_has_every_scenario_and_key_in_whole_tables():
    page = markdown()
    assert page.startswith("# Scenes and configuration keys\n")
    rows = [line for line in page.splitlines() if line.startswith("|")]
    for table in page.split("\n\n"):  # every row as many cells as its table's header
        cells = {len(re.findall(r"(?<!\\)\|", row)) for row in table.splitlines()
                 if row.startswith("|")}
        assert len(cells) <= 1, table
    named = {cell for row in rows
             for cell in [row.split(" | ")[0].removeprefix("| ").replace("\\|", "|")]}
    keys = {key for cell in named if cell.startswith("`") and not cell.startswith("`key")
            for key in _expanded(cell.strip("`").split("`")[0])}
    assert SCHEMA <= keys
    assert {f"`{name}`" for name in SCENARIOS} <= {cell.split(" ")[0] for cell in named}


def _help_keys(help_text):
    """The keys the help names (``  key=default`` at the start of a line)."""
    return {key for line in help_text.splitlines()
            if (m := re.match(r"  ([\w.|]+)=", line)) for key in _expanded(m[1])}


def test_the_text_has_every_scenario_and_key():
    help_text = text(width=80)
    assert _help_keys(help_text) == SCHEMA
    for name in SCENARIOS:
        assert re.search(rf"^  {name} +\S", help_text, re.M), name


@pytest.mark.parametrize("flag", ["--help", "-h"])
def test_python_m_sim_help_prints_the_reference_without_numba_or_hydra(flag):
    out = subprocess.run([sys.executable, "-X", "importtime", "-m", "sim", flag],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("usage: python -m sim")
    for boilerplate in HYDRA_HELP:
        assert boilerplate not in out.stdout
    assert _help_keys(out.stdout) == SCHEMA
    for name in SCENARIOS:
        assert re.search(rf"^  {name} +\S", out.stdout, re.M), name
    assert "docs/" in out.stdout
    loaded = {line.rpartition("|")[2].strip() for line in out.stderr.splitlines()}
    assert not {m for m in loaded if m.split(".")[0] in ("numba", "hydra", "numpy")}


def test_the_sim_command_prints_the_same(monkeypatch, capsys):
    monkeypatch.setattr(sys, "argv", ["sim", "--help"])
    sim.__main__.main()
    assert capsys.readouterr().out == text() + "\n"


def test_help_into_a_pipe_its_reader_closed_is_quiet():
    with subprocess.Popen([sys.executable, "-m", "sim", "--help"], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True) as process:
        process.stdout.close()
        err = process.stderr.read()
        assert process.wait(timeout=120) == 0 and err == ""


def test_hydra_help_is_hydras():
    out = subprocess.run([sys.executable, "-m", "sim", "--hydra-help"], capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0 and out.stdout.startswith("Hydra ("), out.stderr
    assert "--hydra-help : Hydra's help" in out.stdout


def test_the_command_writes_the_markdown_page(capsys):
    config_reference.main(["--markdown"])
    assert capsys.readouterr().out == markdown() + "\n"
