"""The README's numbers, made from the files in ``docs/results/`` that the make targets write.

A region of the README between ``<!-- results: NAME -->`` and ``<!-- end results -->`` is
made by ``REGIONS[NAME]`` from its file; ``make readme`` writes them, and
``tests/test_docs.py`` fails when one is stale. Nothing else of the README is generated.
"""

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
RESULTS = ROOT / "docs" / "results"
REGION = re.compile(r"(<!-- results: (\S+) -->\n)(.*?)(<!-- end results -->)", re.S)


def speed(text):
    """The speed table as ``make speed`` wrote it."""
    return text


def validation(text):
    """One line: how many rows of the validation table pass."""
    rows = [line for line in text.splitlines()[2:] if line.startswith("|")]
    passed = sum(" pass |" in row for row in rows)
    return (f"`make validate` last compared {len(rows)} measurements with their theory or "
            f"published data: {passed} within tolerance.\n")


#: region name: (file in docs/results, the function that renders it)
REGIONS = {"speed": ("speed.md", speed), "validation": ("validation.md", validation)}


def rendered(readme):
    """``readme`` with every region made anew from its file."""
    def fill(match):
        name = match.group(2)
        filename, render = REGIONS[name]
        return match.group(1) + render((RESULTS / filename).read_text()) + match.group(4)

    return REGION.sub(fill, readme)


if __name__ == "__main__":
    text = README.read_text()
    new = rendered(text)
    README.write_text(new)
    print("README.md: " + ("regions made anew" if new != text else "up to date"),
          file=sys.stderr)
