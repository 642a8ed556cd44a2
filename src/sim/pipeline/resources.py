"""What a run will need, checked before it starts: memory, and room on the disk for its file.

The estimates come from the config alone (no engine is built):

* memory: :data:`BASE_BYTES` for the interpreter and the compiled code, :data:`DISK_BYTES`
  per disk (the engine's state of about 290 bytes, twice while it renumbers disks, with the
  placement and the arrays of a snapshot), the frames buffered between flushes, and what
  the observers hold while they compute (the pair distances of g(r), the grid of local
  fields);
* the run file: the frames the stop conditions allow (32 bytes per disk and frame for
  positions and velocities, the observables and observers' values), two checkpoints and,
  with ``observe.event_log``, 48 bytes per contact. With stop conditions that bound no count
  of frames (a run to an energy fraction, say), only what is known is counted.

:func:`check` refuses, with a :class:`sim.pipeline.config.ConfigError` naming the key that drives
the estimate, a run that needs more memory than the machine has available or more disk than the
run folder's file system has free; :func:`warn_large` says when a file will exceed
:data:`LARGE_FILE_BYTES`.
"""

import math
import os
import shutil
import sys
from pathlib import Path

from omegaconf import OmegaConf

from sim.pipeline.config import ConfigError
from sim.pipeline.scenes import SCENES, box_packing, given_count

BASE_BYTES = 400 << 20
DISK_BYTES = 700
#: bytes of one pair distance of g(r) as scipy returns it (i, j, distance), and its copy
PAIR_BYTES = 48
CHECKPOINT_BYTES_PER_DISK = 320
LOG_ROW_BYTES = 48
#: frames buffered in memory before a flush (sim.storage.h5md.RunWriter's buffer_bytes)
BUFFER_BYTES = 64 << 20
#: a projected run file above this size is announced before the run starts
LARGE_FILE_BYTES = 4 << 30
#: gzip keeps 0.95 of the positions and velocities of a gas, 0.93 of the positions of a
#: crater bed but 0.27 of its velocities, most of them zero: a run file keeps at least this
#: fraction of its raw size (the refusal counts no more)
SURELY_KEPT = 0.45


def disk_count(cfg):
    """The number of disks the scene of ``cfg`` makes, and the key that sets it; ``disks.n``
    for a scene the registry lacks (a stored config that was not validated may name one)."""
    scene = SCENES.get(cfg.scene)
    return given_count(cfg) if scene is None else scene.disk_count(cfg)


def _packing_fraction(cfg, n):
    scene = SCENES.get(cfg.scene)
    return box_packing(cfg, n) if scene is None else scene.packing_fraction(cfg, n)


def _local_cells(cfg):
    cells = cfg.observe.local_fields.cells
    if cells is None:
        return 0
    lx, ly = (float(side) for side in cfg.box.size)
    return int(cells) * max(1, round(int(cells) * ly / lx))


def frame_bytes(cfg):
    """Bytes one snapshot adds to the run file, and the key of its largest part."""
    n, n_key = disk_count(cfg)
    parts = {n_key: 32 * n + 256}
    o = cfg.observe
    if o.radial_distribution.bins is not None:
        parts["observe.radial_distribution.bins"] = 8 * int(o.radial_distribution.bins)
    if o.clusters.gap is not None:
        parts[n_key] += 4 * n
    if o.local_fields.cells is not None:
        parts["observe.local_fields.cells"] = 16 * _local_cells(cfg)
    key = max(parts, key=parts.get)
    return sum(parts.values()), key


def frames(cfg):
    """How many snapshots the stop conditions allow at most (None: no bound that the config
    makes sure of, as with a wall-clock budget), and the cadence key that sets it."""
    n, _ = disk_count(cfg)
    s, out = cfg.stop, cfg.output
    if s.wall_seconds is not None:  # the budget may end the run long before the counts
        return None, "stop.wall_seconds"
    if out.every_time is not None and out.every_collisions is None:
        if s.time is None:
            return None, "output.every_time"
        return math.floor(float(s.time) / float(out.every_time)) + 2, "output.every_time"
    cadence = int(out.every_collisions) if out.every_collisions is not None else n
    bounds = [b for b in (s.collisions, s.contacts) if b is not None]
    if not bounds:
        return None, "output.every_collisions"
    return int(min(bounds)) // cadence + 2, "output.every_collisions"


def estimate(cfg):
    """``{"memory": (bytes, key), "file": (bytes, key)}`` for a validated config (see the
    module docstring); the file's bytes count only what the config bounds."""
    n, n_key = disk_count(cfg)
    phi = _packing_fraction(cfg, n)
    one_frame, frame_key = frame_bytes(cfg)
    memory = {n_key: BASE_BYTES + DISK_BYTES * n,
              "output.every_collisions": min(BUFFER_BYTES, one_frame) + one_frame}
    rdf = cfg.observe.radial_distribution
    if rdf.bins is not None:
        pairs = n * 2.0 * phi * float(rdf.r_max) ** 2
        memory["observe.radial_distribution.r_max"] = int(PAIR_BYTES * pairs)
        memory["observe.radial_distribution.bins"] = 32 * int(rdf.bins)
    if cfg.observe.local_fields.cells is not None:
        memory["observe.local_fields.cells"] = 64 * _local_cells(cfg)
    count, cadence_key = frames(cfg)
    file_parts = {n_key: 2 * CHECKPOINT_BYTES_PER_DISK * n}
    if count is not None:
        key = frame_key if frame_key != n_key else cadence_key
        file_parts[key] = file_parts.get(key, 0) + count * one_frame
    if cfg.observe.event_log:
        contacts = cfg.stop.contacts if cfg.stop.contacts is not None else cfg.stop.collisions
        if contacts is not None:
            file_parts["observe.event_log"] = LOG_ROW_BYTES * int(contacts)
    return {"memory": (sum(memory.values()), max(memory, key=memory.get)),
            "file": (sum(file_parts.values()), max(file_parts, key=file_parts.get))}


#: the memory files of a control group, v2 then v1: (limit, usage)
CGROUP_FILES = (("", "memory.max", "memory.current"),
                ("memory", "memory.limit_in_bytes", "memory.usage_in_bytes"))


def _cgroup_room():
    """Bytes left under the memory limits of this process's control groups (v2 or v1; the
    tightest limit along each group's path, a job's under a scheduler's), or inf."""
    room = math.inf
    try:
        groups = Path("/proc/self/cgroup").read_text().splitlines()
    except OSError:
        return room
    for line in groups:
        _, controllers, path = line.split(":", 2)
        for controller, limit_file, usage_file in CGROUP_FILES:
            if controller not in controllers.split(","):  # v2 lists none: ""
                continue
            base = Path("/sys/fs/cgroup", controller)
            folder = base / path.lstrip("/")
            while folder.is_relative_to(base):
                try:
                    limit = int(Path(folder, limit_file).read_text())
                    usage = int(Path(folder, usage_file).read_text())
                    room = min(room, limit - usage)
                except (OSError, ValueError):  # no such file, or "max": no limit here
                    pass
                if folder == base:
                    break
                folder = folder.parent
    return room


def available_memory():
    """Bytes of memory this process may still take: what the kernel calls available, or
    the room left under its control groups' limits when that is smaller."""
    available = math.inf
    try:
        with open("/proc/meminfo") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    available = int(line.split()[1]) * 1024
    except OSError:
        pages = os.sysconf("SC_AVPHYS_PAGES") if hasattr(os, "sysconf") else -1
        if pages > 0:
            available = pages * os.sysconf("SC_PAGE_SIZE")
    return min(available, _cgroup_room())


def _size(nbytes):
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if nbytes >= scale:
            return f"{nbytes / scale:.3g} {unit}"
    return f"{nbytes / 1e3:.3g} kB"


def _existing_parent(folder):
    folder = Path(folder).resolve()
    while not folder.exists():
        folder = folder.parent
    return folder


def check(configs, folder, concurrent=1, job_memory=None):
    """Refuse runs that cannot fit (:class:`ConfigError` naming the key that drives the
    estimate): the ``concurrent`` largest of ``configs`` (one run's, or a sweep's jobs) in
    memory at once — or each within ``job_memory`` bytes, a scheduler's limit per job — and
    the files of all of them on the disk of ``folder``."""
    needs = [(estimate(cfg), cfg) for cfg in configs]
    if job_memory is None:
        largest = sorted(needs, key=lambda need: need[0]["memory"][0])[-concurrent:]
        memory = sum(need["memory"][0] for need, _ in largest)
        room, where = available_memory(), "the machine has"
    else:
        largest = [max(needs, key=lambda need: need[0]["memory"][0])]
        memory, room, where = largest[0][0]["memory"][0], job_memory, "a job may take"
    if memory > room:
        (need, cfg) = largest[-1]
        key = need["memory"][1]
        at_once = f" ({len(largest)} jobs at once)" if len(largest) > 1 else ""
        raise ConfigError(key, _value(cfg, key),
                          f"a run that fits in memory: it needs about {_size(memory)}"
                          f"{at_once}, {where} {_size(room)}")
    nbytes = sum(need["file"][0] for need, _ in needs)
    free = shutil.disk_usage(_existing_parent(folder)).free
    if SURELY_KEPT * nbytes > free:
        need, cfg = max(needs, key=lambda need: need[0]["file"][0])
        key = need["file"][1]
        files = f" ({len(needs)} run files)" if len(needs) > 1 else ""
        raise ConfigError(key, _value(cfg, key),
                          f"a run file that fits on the disk: it would take at least "
                          f"{_size(SURELY_KEPT * nbytes)}{files}, {_existing_parent(folder)} "
                          f"has {_size(free)} free (fewer snapshots: a larger "
                          f"output.every_collisions or output.every_time)")


def warn_large(cfg):
    """One line on stderr when the run file will exceed :data:`LARGE_FILE_BYTES`."""
    nbytes, key = estimate(cfg)["file"]
    if nbytes > LARGE_FILE_BYTES:
        value = _value(cfg, key)
        print(f"sim: warning: the run file will take up to {_size(nbytes)} "
              f"({key}={'null' if value is None else value}); fewer snapshots make it smaller",
              file=sys.stderr)


def _value(cfg, key):
    return OmegaConf.select(cfg, key, default=None)
