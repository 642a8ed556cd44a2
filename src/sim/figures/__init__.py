"""Figure stages: each reads run files (never simulates) and writes a PNG plus the numbers
behind it. ``python -m sim.figures`` (``make figures``) makes the runs a stage needs — skipping
those whose resolved config is unchanged — and then draws every stage.

A stage is a module here with ``NAME``, ``runs(quick) -> {label: [overrides]}`` and/or
``sweeps(quick) -> {label: [overrides with comma lists]}``, and
``draw(runs, sweeps, out_dir)`` taking the run-file paths and sweep directories by label.
"""

STAGES = ("single_disk", "two_disks", "scattering", "gas_snapshot", "maxwell_boltzmann", "mixture",
          "mixture_cooling", "crater_grid", "crater_radius", "crater_speed", "crater_gravity",
          "rough_cooling", "crater_rough", "jamming", "stepped_potentials", "movies")
#: the folder of the quick figures (``--quick``), inside the figures folder
QUICK_FOLDER = "quick"
