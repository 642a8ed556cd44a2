"""How a run can end when its physics leaves what the engine can follow: each error names its
cause in ``stop_reason`` (recorded in the run file), and its message, one line, says what to
change."""


class PhysicsBreakdown(RuntimeError):
    """The run cannot go on: the dynamics left what the engine can follow. Each kind names
    its cause in the class attribute ``stop_reason`` (recorded in the run file), and its
    message, one line, says what to change."""


class StalledError(PhysicsBreakdown):
    """Events keep arriving without the clock advancing: a numerical breakdown."""

    stop_reason = "stalled"


class ClosedBoxError(PhysicsBreakdown):
    """Moving walls have squeezed the disks to jamming, or closed the box."""

    stop_reason = "closed_box"


class InelasticCollapseError(PhysicsBreakdown):
    """Inelastic collapse: a few disks collide infinitely often in finite time."""

    stop_reason = "inelastic_collapse"

    def __init__(self, disks, time, collisions):
        self.disks = disks
        self.time = time
        shown = ", ".join(str(d) for d in disks[:10]) + (" …" if len(disks) > 10 else "")
        super().__init__(
            f"inelastic collapse at t = {time:.17g} after {collisions} disk collisions: disks "
            f"[{shown}] collide ever faster (consecutive contacts less than the collapse "
            f"interval apart). Hard disks with restitution < 1 can collide infinitely often in "
            f"finite time; switch on the TC model (tc.time, far below the mean free time; the "
            f"crater scene uses 1e-8) so that contacts closer than t_c are elastic."
        )


class GrowthLimitError(PhysicsBreakdown):
    """Growing disks have reached the largest radii their box holds without jamming first
    (a small periodic box: the nearest image of a pair is no longer the one that touches)."""

    stop_reason = "growth_limit"
