"""Where the solves run: a local process pool (default) or a Ray cluster.

Both take a picklable function and jobs and yield the results as they
finish, in any order; the caller stores each one durably before asking for
the next. Each worker process builds the NLP once and reuses it for every
job it receives (:func:`~roughwalk.learning.problem_spec.build_problem`).
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
from collections.abc import Callable, Iterator, Sequence
from typing import Any, Protocol, TypeVar

from roughwalk.errors import ConfigError

__all__ = ["Executor", "LocalExecutor", "RayExecutor", "make_executor"]

J = TypeVar("J")
R = TypeVar("R")


class Executor(Protocol):
    """Runs ``fn`` on every job and yields the results as they finish."""

    name: str

    def run(self, fn: Callable[[Any], Any], jobs: Sequence[Any]) -> Iterator[Any]:
        """Results of ``fn(job)`` for every job, in completion order."""
        ...


class LocalExecutor:
    """A pool of ``workers`` processes on this machine; one worker runs in this process.

    Parameters
    ----------
    workers:
        Number of worker processes (≥ 1).

    """

    name = "local"

    def __init__(self, workers: int = 1) -> None:
        if workers < 1:
            raise ConfigError(f"workers must be ≥ 1, got {workers}")
        self.workers = workers

    def run(self, fn: Callable[[J], R], jobs: Sequence[J]) -> Iterator[R]:
        """Results of ``fn(job)`` for every job, in completion order."""
        if self.workers == 1 or len(jobs) <= 1:
            for job in jobs:
                yield fn(job)
            return
        # Forked workers would inherit CasADi's state mid-flight; spawn them clean.
        context = multiprocessing.get_context("spawn")
        with cf.ProcessPoolExecutor(self.workers, mp_context=context) as pool:
            futures = [pool.submit(fn, job) for job in jobs]
            try:
                for future in cf.as_completed(futures):
                    yield future.result()
            finally:
                for future in futures:
                    future.cancel()


class RayExecutor:
    """Tasks on a Ray cluster (Ray's own API), one CPU each.

    Parameters
    ----------
    address:
        The cluster's address ("auto", "ray://host:10001", "host:6379");
        None starts or joins a local instance. An already initialised Ray
        (``ray.init`` called by the caller) is used as it is.

    """

    name = "ray"

    def __init__(self, address: str | None = None) -> None:
        try:
            import ray
        except ImportError:
            raise ConfigError(
                "the ray executor needs Ray: pip install 'roughwalk[ray]' (or pip install ray)"
            ) from None
        self._ray = ray
        if not ray.is_initialized():
            ray.init(address=address, include_dashboard=False, log_to_driver=False)

    def run(self, fn: Callable[[J], R], jobs: Sequence[J]) -> Iterator[R]:
        """Results of ``fn(job)`` for every job, in completion order."""
        ray = self._ray
        remote = ray.remote(num_cpus=1)(fn)
        pending = [remote.remote(job) for job in jobs]
        try:
            while pending:
                done, pending = ray.wait(pending, num_returns=1)
                yield ray.get(done[0])
        finally:
            for ref in pending:
                ray.cancel(ref)


def make_executor(name: str = "local", *, workers: int = 1, address: str | None = None) -> Executor:
    """The executor named ``name``: "local" (``workers`` processes) or "ray" (at ``address``)."""
    if name == "local":
        return LocalExecutor(workers)
    if name == "ray":
        return RayExecutor(address)
    raise ConfigError(f"unknown executor {name!r}; known: local, ray")
