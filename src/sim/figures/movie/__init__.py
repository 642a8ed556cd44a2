"""Movies of runs: :func:`make_movie`, and the ``sim-movie`` command (:func:`main`,
:mod:`sim.figures.movie.cli`)."""

from sim.figures.movie.cli import main
from sim.figures.movie.make import make_movie

__all__ = ["main", "make_movie"]
