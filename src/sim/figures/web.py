"""Web versions of the figures, for the documentation's gallery.

``python -m sim.figures.web`` (run by ``make figures``) writes each stage's PNG of
``outputs/figures/`` into ``docs/results/figures/``, at most :data:`LARGEST_IMAGE` bytes and
:data:`WIDEST` pixels wide, with its numbers files, so that a clone of the repository shows
them.

An image is scaled down (Lanczos) to :data:`WIDEST` pixels and saved optimised; one still
too large is reduced to a palette of 256 colours, then narrowed until it fits (its bytes go
about as its pixels). Numbers files (``<figure>.csv``, ``.txt``) are copied when at most
:data:`LARGEST_NUMBERS` bytes; the gallery shows those up to its own table limit.
"""

import argparse
import io
import math
import shutil
from pathlib import Path

from PIL import Image

from sim.figures import STAGES
from sim.figures.making import stage_module

#: the largest web image, bytes
LARGEST_IMAGE = 150_000
#: the widest web image, pixels
WIDEST = 1000
#: the largest numbers file copied beside it, bytes
LARGEST_NUMBERS = 20_000


def web_png(image):
    """The bytes of ``image`` (a PIL image) as a PNG of at most :data:`LARGEST_IMAGE` bytes
    and :data:`WIDEST` pixels wide."""
    image = image.convert("RGB")
    width = min(WIDEST, image.width)
    palette = False
    while True:
        height = max(1, round(image.height * width / image.width))
        scaled = image.resize((width, height), Image.Resampling.LANCZOS)
        if palette:
            scaled = scaled.quantize(256, method=Image.Quantize.FASTOCTREE)
        data = io.BytesIO()
        scaled.save(data, "PNG", optimize=True)
        if data.tell() <= LARGEST_IMAGE or width <= 100:
            return data.getvalue()
        if palette:  # the bytes go about as the pixels: narrow to fit, a little under
            width = int(width * min(0.9, 0.95 * math.sqrt(LARGEST_IMAGE / data.tell())))
        palette = True


def publish(source, target):
    """Write the web version of every stage's figure in ``source`` into ``target``, with its
    numbers files; returns the files written."""
    target.mkdir(parents=True, exist_ok=True)
    written = []
    for stage_name in STAGES:
        name = stage_module(stage_name).NAME
        image = source / f"{name}.png"
        if not image.exists():
            continue
        with Image.open(image) as opened:
            (target / image.name).write_bytes(web_png(opened))
        written.append(target / image.name)
        for numbers in sorted(source.glob(f"{name}*.csv")) + sorted(source.glob(f"{name}*.txt")):
            if numbers.stat().st_size <= LARGEST_NUMBERS:
                shutil.copyfile(numbers, target / numbers.name)
                written.append(target / numbers.name)
    return written


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m sim.figures.web",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, default=Path("outputs/figures"),
                        help="the figures (default outputs/figures)")
    parser.add_argument("--target", type=Path, default=Path("docs/results/figures"),
                        help="the web versions (default docs/results/figures)")
    args = parser.parse_args(argv)
    for path in publish(args.source, args.target):
        print(path, flush=True)


if __name__ == "__main__":
    main()
