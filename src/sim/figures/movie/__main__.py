"""``python -m sim.figures.movie``: the ``sim-movie`` command."""

import sys

from sim.figures.movie.cli import main

sys.exit(main())
