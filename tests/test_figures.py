"""Figure stages on small runs: they write a PNG and the numbers behind it, and the numbers
say what the figure claims. The quick suite draws the stages whose runs are small and use the
canonical compiled variants (``variants.py``); ``make validate`` draws them all, as
``make figures QUICK=1`` does."""

from pathlib import Path

import numpy as np
import pytest

from sim.figures import STAGES
from sim.figures.__main__ import main
from sim.figures.making import batches

FIGURES = {"single_disk": "fig01_single_disk", "two_disks": "fig02_two_disks",
           "scattering": "fig03_scattering", "gas_snapshot": "fig04_gas_snapshot",
           "maxwell_boltzmann": "fig05_maxwell_boltzmann", "mixture": "fig06_mixture",
           "mixture_cooling": "fig07_mixture_cooling", "crater_grid": "fig08_crater_grid",
           "crater_radius": "fig09_crater_radius", "crater_speed": "fig10_crater_speed",
           "crater_gravity": "fig11_crater_gravity", "rough_cooling": "fig12_rough_cooling",
           "crater_rough": "fig13_crater_rough", "jamming": "fig14_jamming",
           "stepped_potentials": "fig15_stepped_potentials"}
#: the stages the quick suite draws: those of runs that last a second or so (the mixture's
#: sweep of two runs of 1000 disks, and equipartition, a row of the validation table, are
#: ``make validate``'s)
QUICK_STAGES = ("single_disk", "two_disks", "gas_snapshot", "maxwell_boltzmann")


def numbers(out, stage):
    return np.loadtxt(out / f"{FIGURES[stage]}.csv", delimiter=",", skiprows=1)


def key_values(out, stage):
    return dict(line.split("=") for line in (out / f"{FIGURES[stage]}.txt").read_text().split())


def check_single_disk(out):
    path = numbers(out, "single_disk")
    x, y, distance, energy = path[:, 2], path[:, 3], path[:, 4], path[:, 5]
    radius = 0.05
    # every snapshot on the tilted rectangle |x − 1/2| + |y − 1/2| = 1/2 − R, and the
    # distance the figure draws is the distance from it
    np.testing.assert_allclose(np.abs(x - 0.5) + np.abs(y - 0.5), 0.5 - radius, atol=1e-9)
    np.testing.assert_allclose(distance, np.abs(np.abs(x - 0.5) + np.abs(y - 0.5)
                                                - (0.5 - radius)) / np.sqrt(2), rtol=1e-6)
    assert np.all(energy == energy[0])  # elastic walls only reverse a component


def check_two_disks(out):
    two = key_values(out, "two_disks")
    # defocusing by 2ℓ/R at most per collision: order is lost no sooner than it predicts, and
    # within twice that; the growth measured is below 2ℓ/R
    predicted = float(two["predicted_collisions"])
    assert predicted <= float(two["order_lost_after_collisions"]) <= 2 * predicted
    assert 1 < float(two["growth_per_collision"]) < float(two["defocusing_2l_over_r"])


def check_scattering(out):
    scattering = numbers(out, "scattering")
    np.testing.assert_allclose(scattering[:, 2], scattering[:, 3], atol=1e-9)


def check_maxwell_boltzmann(out):
    mb = key_values(out, "maxwell_boltzmann")
    assert float(mb["ks_pvalue"]) > 1e-3
    # the shape of the distribution settles no sooner than its mean, and at K near 2
    assert 0 < float(mb["equilibration_by_the_mean_speed_alone"]) \
        <= float(mb["equilibration_collisions"]) < 10 * float(mb["disks"])
    assert abs(float(mb["late_speed_moment_ratio"]) - 2.0) < 0.05


def check_mixture(out):
    mixture = numbers(out, "mixture")
    assert np.all(mixture[:, 2] > 1e-3)  # both species Maxwellian at the common T
    # equipartition, T₂/T₁ = 1, within four standard errors of the independent runs
    ratio, error = mixture[0, 4], mixture[0, 5]
    assert error > 0 and abs(ratio - 1.0) < 4 * error


def check_mixture_cooling(out):
    # restitution, Garzó–Dufty ratio, DSMC's ± error, measured ± error, measured/DSMC − 1
    # ± error, measured/GD − 1 ± error, T at the end /DSMC − 1 ± error, /Haff − 1 ± error,
    # runs, L_c (ξ rising)
    cooling = numbers(out, "mixture_cooling")
    assert np.all(np.diff(cooling[:, 0]) > 0) and cooling[-1, 0] == 1.0
    assert np.all(np.diff(cooling[:, 4]) < 0)  # the ratio grows as ξ falls, as predicted
    # within five standard errors of DSMC's (the errors of four runs of 800 disks and of DSMC
    # in quadrature; the 0.01 for the error of so few runs' error), and every box below the
    # instability length
    assert np.all(cooling[:, 3] > 0) and np.all(cooling[:, 5] > 0)
    assert np.all(np.abs(cooling[:, 6]) < 5 * cooling[:, 7] + 0.01)
    # the cooling in time: as DSMC's from the same start, and as Haff's law from the window
    assert np.all(np.abs(cooling[:, 10]) < 5 * cooling[:, 11] + 0.03)
    assert np.all(np.abs(cooling[:, 12]) < 5 * cooling[:, 13] + 0.03)
    assert np.all(cooling[:, 15] > 1.0)
    # the window's effect: the mean from every start, with its error, near the chosen one's
    window = np.loadtxt(out / "fig07_mixture_cooling_window.csv", delimiter=",", skiprows=1)
    assert window.shape[1] == 4 and np.all(window[:, 3] > 0)
    for xi, measured, error in cooling[:, [0, 4, 5]]:
        starts = window[window[:, 0] == xi]
        assert np.all(np.abs(starts[:, 2] - measured) < 3 * np.hypot(starts[:, 3], error))


def check_crater_grid(out):
    grid = numbers(out, "crater_grid")
    assert np.all(grid[:, 2] > np.pi * 0.05**2)  # the crater is larger than the projectile
    assert np.all(grid[:, 2] < 0.5)  # and smaller than the bed
    # less the cells the projectile covers: smaller where a cell lies wholly under it
    assert np.all((grid[:, 3] >= 0) & (grid[:, 3] <= grid[:, 2]))
    assert np.any(grid[:, 3] < grid[:, 2])


def check_crater_radius(out):
    radius = numbers(out, "crater_radius")
    # larger projectiles dig larger craters (means over the beds that did not reach the
    # floor; NaN where every bed did)
    reached = np.isnan(radius[:, 2])
    assert np.all(np.diff(radius[~reached, 2]) > 0) and np.all(radius[reached, 4] > 0)
    assert radius[0, 4] == 0  # the smallest projectile stays far above the floor


def check_crater_speed(out):
    speed = numbers(out, "crater_speed")
    # no energy scale: the same area at every speed, but for the TC model's fixed t_c, which
    # makes each speed's run another realization: at one speed the area scatters by 4.7 %
    # from seed to seed (standard deviation of 6 seeds, this quick bed), so three runs may
    # spread by up to about 4 standard deviations; a trend with speed would exceed that
    for column in (2, 5):
        assert np.ptp(speed[:, column]) < 0.2 * speed[:, column].mean()


def check_crater_gravity(out):
    # speed, energy, largest cavity ± error, final cavity, beds, local exponent ± error
    gravity = numbers(out, "crater_gravity")
    assert np.all(np.diff(gravity[:, 2]) > 0)  # more energy opens a larger cavity
    assert np.all(gravity[:, 3] > 0) and np.all(gravity[:, 5] >= 2)
    # a cavity larger than the projectile (radius 0.05) mostly closes again; a smaller one
    # is of the size of the dent every impact leaves (0.0015-0.003 in this quick bed)
    opened = gravity[:, 2] > np.pi * 0.05**2
    assert opened.sum() >= 2
    assert np.all(gravity[opened, 4] < 0.5 * gravity[opened, 2])


def check_rough_cooling(out):
    # β, DSMC's T_rot/T_tr and its error, the theory's, measured and its error, measured/DSMC
    # − 1 and its error, …, runs, T_tr at the end /DSMC − 1 ± error, /Haff − 1 ± error: the
    # ratio rises with β, and lies within four standard errors and 3 % of DSMC's (a gas of
    # N = 2000 at φ = 0.005, where DSMC solves the dilute limit), and so does the cooling
    rough = numbers(out, "rough_cooling")
    assert np.all(np.diff(rough[:, 0]) > 0) and np.all(np.diff(rough[:, 4]) > 0)
    assert np.all(rough[:, 2] > 0.0) and np.all(rough[:, 10] >= 4)
    assert np.all(np.abs(rough[:, 6]) < 4 * rough[:, 7] + 0.03)
    assert np.all(rough[:, [12, 14]] > 0)
    assert np.all(np.abs(rough[:, [11, 13]]) < 4 * rough[:, [12, 14]] + 0.03)


def check_crater_rough(out):
    # radius, compared time, smooth area ± error, rough area ± error, rough/smooth ± error,
    # beds, floor-limited beds: at the same time after launch, in the same bed, the rough
    # bed's crater is the smaller one at every radius, and no bed compared reached the floor
    crater = numbers(out, "crater_rough")
    assert np.all(crater[:, 8] >= 2) and np.all(crater[:, 7] > 0)
    assert np.all(crater[:, 6] < 1.0) and np.all(crater[:, 9] == 0)


def check_jamming(out):
    # Γ, γ, φ_J ± spread, z ± spread, rattler fraction, seeds: the mixture jams within a
    # little of the published 0.84–0.853, slower growth jams denser and nearer isostatic
    # (z = 4), the slowest of the quick runs (N = 200) with fewer than 30 % rattlers. The
    # fastest may jam far below isostatic: at γ = 1 one of the two quick packings has 335
    # contacts among 200 disks, yet removing its rattlers one by one leaves no backbone
    jamming = numbers(out, "jamming")
    assert np.all(np.diff(jamming[:, 0]) > 0) and np.all(jamming[:, 7] >= 2)
    assert np.all((0.83 < jamming[:, 2]) & (jamming[:, 2] < 0.86))
    assert jamming[0, 2] > jamming[-1, 2] and jamming[0, 4] > jamming[-1, 4]
    assert abs(jamming[0, 4] - 4.0) < 0.4 and jamming[0, 6] < 0.3


def check_stepped_potentials(out):
    # kT, B₂/σ² ± error, exact, slope, runs: B₂ from ρ → 0 within four errors of the exact
    # value, below the Boyle temperature negative and above it positive; g(r) jumps at each
    # step by e^{−βΔu} within four errors
    virial = numbers(out, "stepped_potentials")
    assert np.all(np.abs(virial[:, 1] - virial[:, 3]) < 4 * virial[:, 2])
    assert virial[0, 0] < 1.70 < virial[1, 0] and virial[0, 1] < 0 < virial[1, 1]
    jumps = key_values(out, "stepped_potentials")
    for k in (0, 1):
        ratio, error = float(jumps[f"jump_{k}_ratio"]), float(jumps[f"jump_{k}_error"])
        assert 0 < error and abs(ratio - float(jumps[f"jump_{k}_expected"])) < 4 * error


def check_movies(out):
    for movie in ("two_disks", "crater", "cooling", "square_well"):
        assert (out / f"movie_{movie}.mp4").stat().st_size > 10_000


def check(out, stages):
    """The PNG of every stage of ``stages``, and what its numbers say."""
    for stage in stages:
        if stage in FIGURES:
            assert (out / f"{FIGURES[stage]}.png").stat().st_size > 10_000
        check_stage = globals().get(f"check_{stage}")
        if check_stage is not None:
            check_stage(out)


def test_quick_figures_of_the_small_scenes(tmp_path):
    main(["--quick", "--out", str(tmp_path), "--jobs", "2", "--only", *QUICK_STAGES])
    out = tmp_path / "quick"
    check(out, QUICK_STAGES)
    # a second call finds its runs and makes none again
    stamp = {p: p.stat().st_mtime for p in out.rglob("run.h5")}
    main(["--quick", "--out", str(tmp_path), "--jobs", "1", "--only", "single_disk"])
    assert {p: p.stat().st_mtime for p in out.rglob("run.h5")} == stamp


def test_stages_that_read_one_run_are_made_in_one_process(tmp_path):
    groups = batches(list(STAGES), True, tmp_path)
    assert sorted(name for group in groups for name in group) == sorted(STAGES)
    # the gas snapshot and its speed distribution read one run, and so do the figure of
    # stepped potentials and the movie of square-well disks splitting
    assert ["gas_snapshot", "maxwell_boltzmann"] in groups
    assert ["stepped_potentials", "movies"] in groups
    assert len(groups) == len(STAGES) - 2


@pytest.mark.slow
def test_quick_figures(tmp_path):
    """Every stage, as ``make figures QUICK=1`` draws them."""
    main(["--quick", "--out", str(tmp_path)])
    check(tmp_path / "quick", STAGES)


def test_web_versions_are_small_and_keep_their_numbers(tmp_path):
    """``python -m sim.figures.web``: an image of noise (which no PNG compresses) comes out
    within the size and width limits, a plain one keeps its width, and the numbers files
    go beside them."""
    from PIL import Image

    from sim.figures import web

    source, target = tmp_path / "figures", tmp_path / "web"
    source.mkdir()
    noise = np.random.default_rng(0).integers(0, 256, (900, 1200, 3), dtype=np.uint8)
    Image.fromarray(noise).save(source / "fig01_single_disk.png")
    Image.new("RGB", (640, 480), "white").save(source / "fig02_two_disks.png")
    (source / "fig01_single_disk.csv").write_text("t,x\n0,0.5\n")
    web.main(["--source", str(source), "--target", str(target)])
    assert sorted(p.name for p in target.iterdir()) == [
        "fig01_single_disk.csv", "fig01_single_disk.png", "fig02_two_disks.png"]
    for name, widest in (("fig01_single_disk.png", web.WIDEST), ("fig02_two_disks.png", 640)):
        assert (target / name).stat().st_size <= web.LARGEST_IMAGE
        with Image.open(target / name) as image:
            assert image.width <= widest and (name != "fig02_two_disks.png"
                                              or image.size == (640, 480))


def test_ctrl_c_stops_the_figures_with_one_line_and_exit_130(tmp_path, monkeypatch, capsys):
    """A KeyboardInterrupt (Ctrl-C, or SIGTERM) while the stages are made: one line, exit
    status 130, no traceback; the stages' workers pass the signal over (their runs stop by
    themselves)."""
    import sim.figures.__main__ as command

    def interrupted(groups, quick, out, jobs):
        raise KeyboardInterrupt
        yield

    monkeypatch.setattr(command, "made", interrupted)
    assert command.main(["--quick", "--out", str(tmp_path), "--only", "single_disk"]) == 130
    said = capsys.readouterr()
    assert said.out == "" and said.err.count("\n") == 1 and "interrupted" in said.err


def test_a_figure_stopped_while_it_is_written_leaves_no_file(tmp_path):
    """``save`` writes the PNG and the PDF whole or not at all: stopped in the middle of
    writing one, neither it nor a hidden partial file is left."""
    import matplotlib.pyplot as plt

    from sim.figures.style import save

    fig, _ = plt.subplots()

    def stopped(path, **options):
        Path(path).write_bytes(b"\x89PNG half")
        raise KeyboardInterrupt

    fig.savefig = stopped
    with pytest.raises(KeyboardInterrupt):
        save(fig, tmp_path, "figure")
    plt.close(fig)
    assert list(tmp_path.iterdir()) == []
