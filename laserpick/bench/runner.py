"""Run a protocol's trials: in this process, in local worker processes, or on a Ray cluster.

Trial k of a run with seed s has seed s + k and depends on nothing else, so the three ways
give the same attempts for the same seed (only the timings differ). Each worker process
builds its own simulator; MuJoCo renders in each with the OpenGL backend chosen before the
run (`robot.gl_backend`), which local workers inherit through the environment.
"""

from __future__ import annotations

import multiprocessing
import os
import sys
import threading
import time
import traceback
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict
from typing import Any

from laserpick.bench.protocols import PROTOCOLS, Options
from laserpick.bench.results import result
from laserpick.robot.gl_backend import choose_gl_backend

Record = dict[str, Any]


Outcome = tuple[list[Record], str | None]


def run_trial(protocol: str, trial: int, seed: int, options: Options) -> Outcome:
    """One trial's attempt records (JSON-ready), or why the trial broke off: the unit of work
    a worker runs. A trial that raises is reported, not lost with the rest of the run."""
    try:
        choose_gl_backend()  # a check here: this process has imported MuJoCo already
        attempts = PROTOCOLS[protocol].run(trial, seed, options)
    except Exception as exc:
        detail = traceback.format_exc(limit=-3)
        return [], f"trial {trial} (seed {seed}) broke off: {exc!r}\n{detail}"
    return [a.as_dict() for a in attempts], None


def _exit_with_parent(parent: int, period_s: float = 0.5) -> None:
    """Worker initializer: end this worker once the process that started it is gone.

    A parent killed by SIGTERM or SIGKILL gets no chance to end its pool, and the orphaned
    workers would go on simulating for the rest of the run, taking the cores from whatever
    runs next. An orphan is adopted by another process, so its parent pid changes."""

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(period_s)
        os._exit(1)

    threading.Thread(target=watch, name="exit-with-parent", daemon=True).start()


def worker_pool(workers: int) -> ProcessPoolExecutor:
    """A pool of `workers` fresh interpreters (spawn: no EGL context or thread is inherited)
    that end themselves when this process goes away."""
    return ProcessPoolExecutor(
        max_workers=workers,
        mp_context=multiprocessing.get_context("spawn"),
        initializer=_exit_with_parent,
        initargs=(os.getpid(),),
    )


def _local(protocol: str, seeds: list[int], options: Options, workers: int) -> Iterator[Outcome]:
    if workers <= 1:
        for trial, seed in enumerate(seeds):
            yield run_trial(protocol, trial, seed, options)
        return
    with worker_pool(workers) as pool:
        futures = [
            pool.submit(run_trial, protocol, trial, seed, options)
            for trial, seed in enumerate(seeds)
        ]
        for future in as_completed(futures):
            yield future.result()


def _ray(protocol: str, seeds: list[int], options: Options, address: str) -> Iterator[Outcome]:
    try:
        import ray
    except ImportError:
        raise SystemExit(
            "--ray needs Ray: pip install 'laserpick[ray]' (on every node of the cluster)"
        ) from None
    ray.init(address=address, ignore_reinit_error=True, log_to_driver=False)
    remote = ray.remote(num_cpus=1)(run_trial)
    pending = [remote.remote(protocol, trial, seed, options) for trial, seed in enumerate(seeds)]
    while pending:
        done, pending = ray.wait(pending, num_returns=1)
        yield ray.get(done[0])


def run(
    protocol: str,
    *,
    trials: int | None = None,
    seed: int = 1,
    options: Options | None = None,
    workers: int = 1,
    ray_address: str | None = None,
    progress: Callable[[int, int, list[Record]], None] | None = None,
) -> dict[str, Any]:
    """Run `trials` trials of `protocol` (default: the paper's number) and return the result
    JSON. progress(done, total, records so far) is called after each finished trial."""
    if not ray_address:  # here or in workers inheriting this environment: check it once
        choose_gl_backend()
    spec = PROTOCOLS[protocol]
    options = options or Options(selection=spec.selection, strategy=spec.strategy)
    n = spec.trials if trials is None else trials
    seeds = [seed + k for k in range(n)]
    t0 = time.perf_counter()
    if ray_address:
        source = _ray(protocol, seeds, options, ray_address)
    else:
        source = _local(protocol, seeds, options, workers)
    records: list[Record] = []
    errors: list[str] = []
    if progress is not None:
        progress(0, n, records)
    for done, (trial_records, error) in enumerate(source, start=1):
        records += trial_records
        if error is not None:
            errors.append(error)
            print(f"laserpick bench: {error}", file=sys.stderr, flush=True)
        if progress is not None:
            progress(done, n, records)
    described = asdict(options) | {"workers": workers, "ray": ray_address}
    out = result(protocol, seed, n, records, described, time.perf_counter() - t0)
    out["errors"] = errors
    return out


def progress_bar(desc: str) -> Callable[[int, int, list[Record]], None]:
    """A progress callback drawing a bar on stderr: trials done, attempts and successes."""
    from tqdm import tqdm

    bar: tqdm | None = None

    def update(done: int, total: int, records: list[Record]) -> None:
        nonlocal bar
        if bar is None:
            bar = tqdm(total=total, desc=desc, unit="trial", file=sys.stderr, initial=0)
        if done == 0:
            return
        ok = sum(r["success"] for r in records)
        bar.set_postfix_str(f"{ok}/{len(records)} attempts ok", refresh=False)
        bar.update(1)
        if done == total:
            bar.close()

    return update
