"""The reference of every scenario and config key: the schema (:mod:`sim.pipeline.schema`: key,
type) joined with the YAML of ``conf/`` (default, and the comments that give meaning, unit
and an example override), rendered as the Markdown page "Scenes and configuration keys"
(:func:`markdown`) and as the terminal's ``python -m sim --help`` (:func:`text`).

The comments are read line by line, the indentation giving each key its dotted path:

- a comment after a key is that key's; a comment line starting right of the key's colon
  continues it, one at a key's indentation introduces the key below;
- a section's comment is its own (a section of a section's prefixes its keys' meanings);
- a section written on one line (``right: {temperature: null, …}``) takes the comments of
  the same keys in the section above it (``left``);
- the keys of the scenes' own sections (``projectile``, ``bed``, …: absent from
  ``conf/config.yaml``) take their comments from the scenario file named after a scene that
  has them (``crater.yaml``, not ``crater_gravity.yaml``).

The paths read must be those the YAML parser finds (:class:`ValueError` otherwise);
``tests/test_config_reference.py`` checks that every key of the schema has its comment and
every commented key is in the schema. It loads neither the engine nor Hydra, so that
``python -m sim --help`` is quick.

    python -m sim.pipeline.config_reference [--markdown]
"""

import argparse
import re
import shutil
import textwrap
from dataclasses import MISSING, dataclass, fields, is_dataclass
from pathlib import Path

import yaml

from sim.pipeline.schema import CONF_DIR, SimConfig, leaf_fields, plain_type

CONF = Path(CONF_DIR)
#: keys set by the scenario files, not by hand (``scenario=NAME`` chooses them)
SET_BY_SCENARIO = ("scene",)
#: sections of ``conf/config.yaml`` that are not keys of a scene
NOT_KEYS = ("defaults", "hydra")
TITLE = "Scenes and configuration keys"
USAGE = (
    ("python -m sim [scenario=NAME] [KEY=VALUE ...]", "run a scene"),
    ("python -m sim [scenario=NAME] KEY=A,B ... -m", "a sweep, jobs in parallel"),
    ("python -m sim resume=RUN_FILE [KEY=VALUE ...]", "continue a stopped run"),
    ("python -m sim --help | --hydra-help", "this text | Hydra's help"),
    ("sim-inspect RUN_FILE [--json]", "what a run file holds"),
)
OUTPUTS = ("A run writes outputs/runs/DATE/TIME/run.h5 (hydra.run.dir=DIR: DIR/run.h5), a sweep "
           "outputs/multirun/DATE/TIME/N/ (hydra.sweep.dir=DIR); sim.analysis.open_run(RUN_FILE) "
           "reads a run as an xarray Dataset, open_sweep(DIR) a sweep. "
           "Exit status 0 done, 1 a run file not written or jobs of a sweep failed, 2 bad input "
           "(nothing written), 3 the physics broke down, 130/143 stopped by Ctrl-C/SIGTERM "
           "(resume= continues).")


@dataclass(frozen=True)
class Key:
    """A row of the reference: its dotted keys (several for sections alike, such as the four
    walls), type, default and meaning."""

    keys: tuple
    kind: str
    default: str
    meaning: str

    @property
    def name(self):
        """``walls.left|right|bottom|top.speed`` for the keys of sections alike."""
        if len(self.keys) == 1:
            return self.keys[0]
        head, _, leaf = self.keys[0].rpartition(".")
        middle = "|".join(key.split(".")[-2] for key in self.keys)
        return f"{head.rpartition('.')[0]}.{middle}.{leaf}"


@dataclass(frozen=True)
class Section:
    """The keys under one top-level name ("" for the top-level keys), with its comment and,
    for a scene's own section, the scenarios that set it."""

    name: str
    about: str
    scenarios: tuple
    keys: tuple


@dataclass(frozen=True)
class Scenario:
    """A file of ``conf/scenario/``: its scene, what it is (a summary and in full), its
    example command and the keys it sets ({key: value})."""

    name: str
    scene: str
    summary: str
    description: str
    example: str
    sets: dict


@dataclass(frozen=True)
class Reference:
    """What the renderings show: the scenario run by default, the scenarios, and the keys in
    sections."""

    default_scenario: str
    scenarios: tuple
    sections: tuple


_KEY = re.compile(r"(?P<indent> *)(?P<key>[\w-]+):(?:\s+(?P<value>.*))?")


def _code_and_comment(line):
    """A YAML line split at its comment: (code, comment text or None)."""
    quote = None
    for i, c in enumerate(line):
        if quote:
            quote = None if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i], line[i + 1:].strip()
    return line, None


def leaves(node, prefix=""):
    """{dotted key: value} of every leaf of a loaded YAML mapping (lists whole)."""
    found = {}
    for key, value in node.items():
        if isinstance(value, dict) and value:
            found.update(leaves(value, f"{prefix}{key}."))
        else:
            found[f"{prefix}{key}"] = value
    return found


def comments(text):
    """The comments of a YAML file, by the rules of the module docstring: (the header, the
    comment lines before the first key; {dotted key or section: comment})."""
    header, found, stack, pending, previous = [], {}, [], [], {}
    last = None  # (column right of the colon, path) of the key whose comment may continue
    for line in text.splitlines():
        code, comment = _code_and_comment(line)
        if not code.strip():
            column = len(line) - len(line.lstrip())
            if comment is None:
                pending, last = [], None
            elif not previous:
                header.append(comment)
            elif last is not None and column >= last[0]:
                found[last[1]] = f"{found.get(last[1], '')} {comment}".strip()
            else:
                pending.append(comment)
                last = None
            continue
        if code.lstrip().startswith("-"):  # an item of a list value
            pending, last = [], None
            continue
        match = _KEY.fullmatch(code.rstrip())
        if match is None:
            raise ValueError(f"not a key: {line!r}")
        indent = len(match["indent"])
        while stack and stack[-1][0] >= indent:
            stack.pop()
        parent = ".".join(key for _, key in stack)
        path = f"{parent}.{match['key']}" if parent else match["key"]
        said = " ".join(pending + ([comment] if comment else []))
        if said:
            found[path] = said
        rest = match["value"] or ""
        if not rest:
            stack.append((indent, match["key"]))
        elif rest.startswith("{") and parent in previous:
            for key in leaves(yaml.safe_load(rest)):
                inherited = found.get(f"{previous[parent]}.{key}")
                if inherited:
                    found[f"{path}.{key}"] = inherited
        previous[parent] = path
        pending, last = [], (indent + len(match["key"]) + 1, path)
    paths = {p for key in leaves(yaml.safe_load(text) or {}) for p in _prefixes(key)}
    if set(found) - paths:
        raise ValueError(f"comments read for keys the YAML lacks: {sorted(set(found) - paths)}")
    return header, found


def _prefixes(key):
    parts = key.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts) + 1)]


def _kind(annotation):
    """``float``, ``float or null``, … of a schema field's type."""
    plain = plain_type(annotation)
    name = getattr(plain, "__name__", str(plain))
    return f"{name} or null" if plain is not annotation else name


def schema_keys():
    """{dotted key: (type, default)} of every leaf of the schema, the keys set by the scenario
    files aside."""
    return {key: (_kind(f.type), f.default_factory() if f.default is MISSING else f.default)
            for key, f in leaf_fields()
            if key not in SET_BY_SCENARIO}


def scene_sections():
    """The schema's sections that only some scenes have (fields of SimConfig defaulting to
    None)."""
    return tuple(f.name for f in fields(SimConfig)
                 if f.default is None and is_dataclass(plain_type(f.type)))


def value(x):
    """A value as an override writes it: ``null``, ``true``, ``[1.0, 1.0]``."""
    if x is None:
        return "null"
    if isinstance(x, bool):
        return str(x).lower()
    if isinstance(x, (list, tuple)):
        return f"[{', '.join(value(item) for item in x)}]"
    return str(x)


def _summary(description):
    """The description up to its first colon, semicolon or full stop outside brackets."""
    depth = 0
    for i, c in enumerate(description):
        depth += (c in "([") - (c in ")]")
        if depth == 0 and (c in ":;" or c == "." and description[i + 1:i + 2] in ("", " ")):
            return description[:i]
    return description


def _scenario(path):
    text = path.read_text()
    header, _ = comments(text)
    words = " ".join(line for line in header if not line.startswith("@package"))
    description, _, example = words.partition("python -m sim")
    sets = leaves(yaml.safe_load(text))
    scene = sets.pop("scene")
    description = description.strip().rstrip(":.")
    return Scenario(path.stem, scene, _summary(description), f"{description}.",
                    f"python -m sim{example}" if example else "", sets)


def scene_comments(scenarios, sections):
    """{key: comment} of the scenes' own sections, from the files named after a scene."""
    found = {}
    for scenario in scenarios:
        if scenario.name == scenario.scene:
            _, said = comments((CONF / "scenario" / f"{scenario.name}.yaml").read_text())
            for key, comment in said.items():
                if key.split(".")[0] in sections:
                    found.setdefault(key, comment)
    return found


def _meaning(key, said):
    """A key's comment, after those of the sections of sections above it."""
    return ": ".join(said[p] for p in _prefixes(key)[1:] or [key] if p in said)


def _rows(said, defaults):
    """The :class:`Key` of every key of the schema, the keys of sections alike (the four
    walls: the same key, type, default and comment) in one."""
    rows = {}
    for key, (kind, default) in schema_keys().items():
        parts = key.split(".")
        alike = (*parts[:-2], "*", parts[-1]) if len(parts) > 2 else tuple(parts)
        shown = value(defaults.get(key, default))
        rows.setdefault((alike, kind, shown, said.get(key)), []).append(key)
    return [Key(tuple(group), kind, shown, _meaning(group[0], said))
            for (_, kind, shown, _), group in rows.items()]


def reference():
    """The :class:`Reference` of ``conf/`` and the schema."""
    text = (CONF / "config.yaml").read_text()
    config = yaml.safe_load(text)
    default_scenario = next(item["scenario"] for item in config["defaults"]
                            if isinstance(item, dict) and "scenario" in item)
    defaults = leaves({k: v for k, v in config.items() if k not in NOT_KEYS})
    scenarios = tuple(_scenario(path) for path in sorted((CONF / "scenario").glob("*.yaml")))
    own = scene_sections()
    said = {**comments(text)[1], **scene_comments(scenarios, own)}
    grouped = {"": []}  # the top-level keys first
    for k in _rows(said, defaults):
        grouped.setdefault(k.keys[0].split(".")[0] if "." in k.keys[0] else "", []).append(k)
    return Reference(default_scenario, scenarios, tuple(
        Section(name, said.get(name, ""),
                tuple(s.name for s in scenarios if name in own
                      and any(key.split(".")[0] == name for key in s.sets)), tuple(group))
        for name, group in grouped.items()))


_OVERRIDE = re.compile(r"((?<![\w.])[\w.]+=(?:\[[^\]]*\]|[^\s;,)]+))")


def _cell(words):
    """Text for a Markdown table cell: overrides as code, pipes and angle brackets escaped."""
    parts = _OVERRIDE.split(words)
    return "".join(f"`{part}`" if i % 2 else part.replace("<", "\\<")
                   for i, part in enumerate(parts)).replace("|", "\\|")


def markdown():
    """The page "Scenes and configuration keys" in Markdown."""
    ref = reference()
    lines = [f"# {TITLE}", "",
             f"A run composes `conf/config.yaml` (the defaults below) with one scenario of "
             f"`conf/scenario/` (`scenario=NAME`, default `{ref.default_scenario}`), then the "
             f"overrides of the command line (`KEY=VALUE`; with `-m`, comma lists sweep). "
             f"`python -m sim --help` prints this page in the terminal; it is made from the "
             f"schema (`sim.pipeline.schema`) and the comments of the YAML files by "
             f"`python -m sim.pipeline.config_reference --markdown`.", "",
             "## Scenarios", "",
             "| scenario | what it is | keys it sets |", "| --- | --- | --- |"]
    for s in ref.scenarios:
        scene = f" (scene `{s.scene}`)" if s.scene != s.name else ""
        example = f" `{s.example}`".replace("|", "\\|") if s.example else ""
        sets = ", ".join(f"`{k}={value(v)}`" for k, v in s.sets.items()).replace("|", "\\|")
        lines.append(f"| `{s.name}`{scene} | {_cell(s.description)}{example} | "
                     f"{sets or 'none: the defaults'} |")
    lines += ["", "## Keys", ""]
    for section in ref.sections:
        title = f"`{section.name}`" if section.name else "Top level"
        lines += [f"### {title}", ""]
        if section.about:
            lines += [_cell(section.about[0].upper() + section.about[1:]) + ".", ""]
        if section.scenarios:
            lines += [f"Set by the scenario{'s' * (len(section.scenarios) > 1)} "
                      f"{', '.join(f'`{s}`' for s in section.scenarios)}; absent from the "
                      f"others.", ""]
        lines += ["| key | default | type | meaning and unit |", "| --- | --- | --- | --- |"]
        for k in section.keys:
            name = k.name.replace("|", "\\|")
            lines.append(f"| `{name}` | `{k.default}` | {k.kind} | {_cell(k.meaning)} |")
        lines.append("")
    return "\n".join(lines)


def text(width=None):
    """The reference for the terminal (``python -m sim --help``), ``width`` columns wide
    (default: the terminal's, 72 to 120)."""
    width = width or min(120, max(72, shutil.get_terminal_size((100, 24)).columns))
    ref = reference()

    def paragraph(words):
        return textwrap.fill(words, width)

    def row(left, right, column):
        if len(left) + 2 > column:
            return [left, *textwrap.wrap(right, width, initial_indent=" " * column,
                                         subsequent_indent=" " * column)]
        return textwrap.wrap(f"{left:<{column}}{right}", width,
                             subsequent_indent=" " * column) or [left]

    column = 7 + max(len(command) for command, _ in USAGE) + 2
    lines = []
    for i, (command, what) in enumerate(USAGE):
        lines += row(f"{'usage:' if i == 0 else '':<7}{command}", what, column)
    lines += ["", paragraph(OUTPUTS), "",
              f"Scenarios (scenario=NAME; default {ref.default_scenario}; each sets keys below):"]
    column = max(len(s.name) for s in ref.scenarios) + 4
    for s in ref.scenarios:
        lines += row(f"  {s.name}", s.summary, column)
    lines += ["", "Keys (KEY=DEFAULT  meaning and unit):"]
    column = 40
    for section in ref.sections:
        about = f": {section.about}" if section.about else ""
        where = (f" (scenario{'s' * (len(section.scenarios) > 1)} "
                 f"{', '.join(section.scenarios)})" if section.scenarios else "")
        lines += ["", paragraph(f"{section.name or 'top level'}{where}{about}")]
        for k in section.keys:
            lines += row(f"  {k.name}={k.default}", k.meaning, column)
    lines += ["", paragraph("More: the documentation (`make docs` in a clone builds it from "
                            "docs/), README.md and ARCHITECTURE.md. This reference as a "
                            "Markdown page:"),
              "  python -m sim.pipeline.config_reference --markdown"]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m sim.pipeline.config_reference",
                                     description="Every scenario and config key.")
    parser.add_argument("--markdown", action="store_true",
                        help=f'the Markdown page "{TITLE}" (default: the terminal\'s text)')
    args = parser.parse_args(argv)
    print(markdown() if args.markdown else text())


if __name__ == "__main__":
    main()
