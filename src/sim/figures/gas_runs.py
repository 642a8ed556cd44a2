"""The gas run that figures 4 and 5 share: N disks started at equal speeds (the seed
study's 10 000), sampled every N/10 collisions for 3N + 200 000 collisions."""


def gas_overrides(quick):
    n = 1000 if quick else 10_000
    collisions = 3 * n + (20_000 if quick else 200_000)
    return n, ["scenario=gas", f"disks.n={n}", f"stop.collisions={collisions}",
               f"output.every_collisions={n // 10}"]
