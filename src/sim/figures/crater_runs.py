"""The crater scene as figures 8–10 run and measure it: the seed study's bed of 4000 disks
(R = 0.0045, φ ≈ 0.51 in the lower half) or, quick, 1000 disks of twice the radius (the same
packing fraction)."""


def crater_overrides(quick):
    bed = ["bed.n=1000", "bed.radius=0.009", "output.every_collisions=5000"] if quick else []
    return ["scenario=crater", *bed]


def require_stop(sweep, swept, reason, remedy):
    """Raise when a run of ``sweep`` (over the dimension ``swept``) stopped otherwise than by
    ``reason``: its crater would be read at another stage than the others'."""
    values = sweep[swept].values
    unfinished = values[sweep["stop_reason"].values != reason]
    if unfinished.size:
        raise ValueError(f"runs at {swept} = {unfinished.tolist()} stopped otherwise than by "
                         f"{reason}: {remedy}")
