"""Hydra callbacks: a sweep reports every job, failed ones included, in its directory.

Each job writes ``<job dir>/job_status.yaml`` (overrides, status, run file or error); at the
end of the sweep ``<sweep dir>/sweep_summary.yaml`` lists them all. A failing job does not
stop the others: in a sweep the job function returns ``{"failed": message}`` instead of
raising, so the launcher runs every job and the entry point exits with status 1 at the end
when any failed. A job a signal stopped returns ``{"stopped": reason}``: status STOPPED (on a
cluster with the signal and its SLURM id, ``{"stopped": reason, "signal": name,
"slurm_job": id}``).
"""

from pathlib import Path

import yaml
from hydra.core.hydra_config import HydraConfig
from hydra.core.utils import JobStatus
from hydra.experimental.callback import Callback
from hydra.types import RunMode

STATUS_FILE = "job_status.yaml"
#: the status of a job a signal stopped (its run file resumes; :mod:`sim.pipeline.sweep_stop`)
STOPPED = "STOPPED"
SUMMARY_FILE = "sweep_summary.yaml"
#: Jobs of the last sweep in this process that failed, and those a signal stopped (read by
#: ``python -m sim``).
FAILED_JOBS = []
STOPPED_JOBS = []


class SweepReport(Callback):
    def on_job_end(self, config, job_return, **kwargs):
        if HydraConfig.get().mode != RunMode.MULTIRUN:
            return
        runtime = HydraConfig.get().runtime
        entry = {"job": HydraConfig.get().job.num,
                 "overrides": list(HydraConfig.get().overrides.task),
                 "status": job_return.status.name}
        value = job_return._return_value
        if job_return.status == JobStatus.COMPLETED and not isinstance(value, dict):
            entry["run_file"] = str(value)
        elif isinstance(value, dict) and "stopped" in value:  # sim.pipeline.sweep_stop
            entry["status"] = STOPPED
            entry["stop_reason"] = value["stopped"]
            # a job on a cluster: the signal and its SLURM id (sim.pipeline.cluster)
            entry |= {key: value[key] for key in ("signal", "slurm_job") if key in value}
        else:
            entry["status"] = JobStatus.FAILED.name
            entry["error"] = (value["failed"] if isinstance(value, dict)
                              else f"{type(value).__name__}: {value}")
        text = yaml.safe_dump(entry, sort_keys=False, allow_unicode=True)
        Path(runtime.output_dir, STATUS_FILE).write_text(text)

    def on_multirun_end(self, config, **kwargs):
        sweep_dir = Path(config.hydra.sweep.dir)
        jobs = [yaml.safe_load(p.read_text()) for p in sorted(sweep_dir.glob(f"*/{STATUS_FILE}"))]
        jobs.sort(key=lambda job: job["job"])
        failed = [job for job in jobs if job["status"] not in ("COMPLETED", STOPPED)]
        stopped = [job for job in jobs if job["status"] == STOPPED]
        summary = {"jobs": len(jobs), "completed": len(jobs) - len(failed) - len(stopped),
                   "failed": len(failed), "stopped": len(stopped), "details": jobs}
        text = yaml.safe_dump(summary, sort_keys=False, allow_unicode=True)
        (sweep_dir / SUMMARY_FILE).write_text(text)
        FAILED_JOBS[:] = failed
        STOPPED_JOBS[:] = stopped
        if failed:
            print(f"sim: {len(failed)} of {len(jobs)} jobs failed; see "
                  f"{sweep_dir / SUMMARY_FILE}")
