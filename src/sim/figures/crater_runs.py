"""The crater scene as figures 8–10 run and measure it: the seed study's bed of 4000 disks
(R = 0.0045, φ ≈ 0.51 in the lower half) or, quick, 1000 disks of twice the radius (the same
packing fraction)."""

import numpy as np


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


def preparation_of(ds):
    """How the runs of ``ds`` (open_run's or open_sweep's) made their initial state, in words:
    one text for all, or each distinct one."""
    if "preparation" in ds:
        texts = dict.fromkeys(str(t) for t in np.ravel(ds["preparation"].values))
    else:
        texts = [ds.attrs.get("preparation", "")]
    return "; ".join(t for t in texts if t) or "preparation not recorded (an older run file)"
