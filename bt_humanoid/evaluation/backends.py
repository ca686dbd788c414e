"""Where episodes run: worker processes on this machine, or a Ray cluster.

Both take the suite file and the episode indices and yield each episode's
record as it finishes, so the caller can show progress. Each local worker
is pinned to its own CPU core: an episode's real-time factor is a one-core
figure whatever the worker count.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any

from bt_humanoid.errors import UserError
from bt_humanoid.evaluation.episode import run_episode
from bt_humanoid.sim.sensor_models import IDEAL_SENSORS_VARIABLE, ideal_sensors_requested


def _pin_worker(cores: list[int], counter) -> None:
    with counter.get_lock():
        slot = counter.value
        counter.value += 1
    if hasattr(os, "sched_setaffinity") and cores:
        os.sched_setaffinity(0, {cores[slot % len(cores)]})


def run_local(
    suite_file: str,
    indices: list[int],
    seed: int,
    workers: int,
    scene: str | None = None,
    plan_only: bool = False,
    robot: str | None = None,
) -> Iterator[dict[str, Any]]:
    """Episodes in ``workers`` processes (spawned: each has its own MuJoCo and renderers), or in this one."""
    cores = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    if workers == 1:
        try:
            if cores:
                os.sched_setaffinity(0, {cores[0]})
            for index in indices:
                yield run_episode(suite_file, index, seed, scene=scene, plan_only=plan_only, robot=robot)
        finally:
            if cores:
                os.sched_setaffinity(0, set(cores))
        return
    context = multiprocessing.get_context("spawn")
    counter = context.Value("i", 0)
    with ProcessPoolExecutor(workers, mp_context=context, initializer=_pin_worker, initargs=(cores, counter)) as pool:
        futures = [
            pool.submit(run_episode, suite_file, index, seed, None, scene, plan_only, robot) for index in indices
        ]
        for future in as_completed(futures):
            yield future.result()


def run_ray(
    suite_file: str,
    indices: list[int],
    seed: int,
    address: str | None,
    scene: str | None = None,
    plan_only: bool = False,
    robot: str | None = None,
) -> Iterator[dict[str, Any]]:
    """Episodes as Ray tasks, one CPU each, on the cluster at ``address`` (or a local Ray instance)."""
    try:
        import ray
    except ImportError:
        raise UserError(
            "--backend ray needs Ray", hint="pip install 'bt-humanoid[ray]', or use --backend local"
        ) from None
    if not ray.is_initialized():
        # a cluster's workers do not inherit this process's environment: --ideal-sensors goes with the tasks
        sensors = {"env_vars": {IDEAL_SENSORS_VARIABLE: "1"}} if ideal_sensors_requested() else None
        ray.init(
            address=address,
            include_dashboard=False,
            log_to_driver=False,
            ignore_reinit_error=True,
            runtime_env=sensors,
        )
    remote = ray.remote(num_cpus=1)(run_episode)
    pending = [remote.remote(suite_file, index, seed, None, scene, plan_only, robot) for index in indices]
    while pending:
        finished, pending = ray.wait(pending, num_returns=1)
        yield ray.get(finished[0])
