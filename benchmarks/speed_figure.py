"""The speed table as a figure: the rates of sim and the C peer against N, and their ratio.

``make speed`` draws it from the JSON that ``peer_speed.py --json`` wrote, as a PNG of at
most ``sim.figures.web.LARGEST_IMAGE`` bytes and ``WIDEST`` pixels. To redraw it without
measuring again:

    python benchmarks/speed_figure.py docs/results/speed.json docs/results/speed.png
"""

import argparse
import io
import json
from pathlib import Path

from PIL import Image

from sim.figures.style import figure, plt
from sim.figures.web import web_png

#: each engine's name in the legend, by the prefix of its fields in the rows
ENGINES = {"c": "C peer", "sim": "sim", "minimal": "minimal numba design"}
#: the marker of each packing fraction φ, in increasing order
MARKERS = "osD^v"


def draw(rows, about=None):
    """The figure of ``rows`` (the rows of peer_speed's JSON, one per N and φ) measured on
    ``about`` (its machine record, if any). Left: each engine's best-chunk rate, collisions
    per second, against N, log–log, with each round's rate as a faint dot when the rows hold
    them. Right: the median over rounds of each engine's rate over the C peer's in the same
    round, bars from the first to the third quartile, a dashed line at 1."""
    fig, (rates, ratios) = figure(ncols=2, width=8.0, height=3.8)
    kinds = [kind for kind in ENGINES if f"{kind}_collisions_per_s" in rows[0]]
    phis = sorted({row["phi"] for row in rows})
    rounds, chunk = rows[0]["rounds"], rows[0]["chunk"]
    for k, phi in enumerate(phis):
        marker = MARKERS[k % len(MARKERS)]
        chosen = sorted((row for row in rows if row["phi"] == phi), key=lambda row: row["n"])
        n = [row["n"] for row in chosen]
        at_phi = f", φ = {phi:g}" if len(phis) > 1 else ""
        for color, kind in enumerate(kinds):
            rates.plot(n, [row[f"{kind}_collisions_per_s"] for row in chosen], f"-{marker}",
                       color=f"C{color}", lw=1, label=f"{ENGINES[kind]}{at_phi}")
            for row in chosen:
                each = row.get(f"{kind}_rates_per_round", [])
                rates.plot([row["n"]] * len(each), each, ".", color=f"C{color}", alpha=0.3,
                           ms=4)
            if kind == "c":
                continue
            median = [row[f"{kind}_over_c"] for row in chosen]
            below = [row[f"{kind}_over_c"] - row[f"{kind}_over_c_q1"] for row in chosen]
            above = [row[f"{kind}_over_c_q3"] - row[f"{kind}_over_c"] for row in chosen]
            ratios.errorbar(n, median, yerr=[below, above], fmt=f"-{marker}", color=f"C{color}",
                            lw=1, capsize=3, label=f"{ENGINES[kind]} / C{at_phi}")
    each_round = any(f"{kind}_rates_per_round" in row for row in rows for kind in kinds)
    rates.set(xscale="log", yscale="log", xlabel="N (disks)",
              ylabel="disk–disk collisions per second")
    rates.set_title(f"rate: best chunk of {rounds} rounds"
                    + ("; dots: each round" if each_round else ""), fontsize=9)
    rates.legend(fontsize=8)
    ratios.axhline(1.0, color="0.3", ls="--", lw=1)
    ratios.set(xscale="log", xlabel="N (disks)", ylabel="rate over the C peer's, same round")
    ratios.set_title(f"ratio: median of {rounds} rounds; bars: quartiles", fontsize=9)
    ratios.set_ylim(bottom=0.0)
    ratios.legend(fontsize=8, loc="lower right")
    lines = [f"Equal elastic disks in a periodic box, φ = {', '.join(f'{p:g}' for p in phis)};"
             f" {rounds} rounds of {chunk:,} collisions per engine, one thread"]
    if about:
        lines.append(f"measured {about['date'][:10]} on {about['processor']} "
                     f"({about['cores']} cores), numba {about['numba']}, {about['compiler']} "
                     f"{about['flags']}")
    fig.suptitle("\n".join(lines), fontsize=9)
    return fig


def write_png(fig, path):
    """Save ``fig`` to ``path`` as a web PNG (``sim.figures.web.web_png``) and close it."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    plt.close(fig)
    with Image.open(buffer) as image:
        Path(path).write_bytes(web_png(image))


def plot(json_path, png_path):
    """Draw the figure of peer_speed's JSON file ``json_path`` into ``png_path``."""
    measured = json.loads(Path(json_path).read_text())
    write_png(draw(measured["rows"], measured.get("machine")), png_path)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("json", help="the JSON file that peer_speed.py --json wrote")
    parser.add_argument("png", help="the figure to write")
    args = parser.parse_args(argv)
    plot(args.json, args.png)


if __name__ == "__main__":
    main()
