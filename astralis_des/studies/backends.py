"""Where a study's chunks run, by registry: ``local`` (a process pool) and ``ray``.

A backend takes the study once per worker and yields chunk results as they finish; the runner
puts the rows back in order.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Generator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from astralis_des import compiled
from astralis_des.errors import InputError
from astralis_des.physics.quiet import quiet_c_output
from astralis_des.registry import Registry, UnknownEntry
from astralis_des.studies.pool import WorkerPool
from astralis_des.studies.scenarios import ChunkResult, failed_scenario, run_chunk

if TYPE_CHECKING:
    from astralis_des.studies.spec import Study

log = logging.getLogger(__name__)


class Backend(Protocol):
    name: str  # as registered
    workers: int

    def run(self, study: Study, chunks: Sequence[list[int]],
            recordings: Path | None) -> Generator[ChunkResult, None, None]: ...

    def hold(self, base: Study) -> None:
        """Keep the workers for the runs that follow, of studies made from ``base`` by
        ``with_changes`` (a tune's trials), until :meth:`close`."""

    def close(self) -> None: ...


BACKENDS: Registry[str, Callable[[int, str | None], Backend]] = Registry("study backend")


def make_backend(name: str, workers: int, address: str | None = None) -> Backend:
    try:
        return BACKENDS.get(name)(workers, address)
    except UnknownEntry as exc:
        raise InputError(str(exc), key="backend") from None


# -- local: one process, or a pool of worker processes -----------------------------------
class LocalBackend:
    """This process for one worker, else a :class:`WorkerPool`: processes that each hold the
    study, and that are replaced when one dies."""

    name = "local"

    def __init__(self, workers: int, address: str | None = None) -> None:
        if address is not None:
            raise InputError("the local backend takes no address (it is for ray)",
                             key="address")
        self.workers = max(1, workers)
        self._held: WorkerPool | None = None

    def hold(self, base: Study) -> None:
        """One pool for the runs that follow, its workers holding ``base``: a study made from
        it by ``with_changes`` is sent as its changes, and what the workers keep on the world
        (free floor, furnished rooms) lasts from one run to the next."""
        self.close()
        if self.workers > 1:
            self._held = WorkerPool(base, self.workers)

    def close(self) -> None:
        if self._held is not None:
            self._held.close()
            self._held = None

    def run(self, study: Study, chunks: Sequence[list[int]],
            recordings: Path | None) -> Generator[ChunkResult, None, None]:
        indices = [i for chunk in chunks for i in chunk]
        if self.workers == 1 or len(indices) == 1:
            if len(indices) >= compiled.MANY:  # this process runs them all
                compiled.enable()
            for chunk in chunks:
                yield run_chunk(study, chunk, recordings)
            return
        held = self._held
        if held is not None and study.origin is not None and study.origin[0] is held.base:
            yield from held.run(study, study.origin[1], indices, recordings)
            return
        pool = WorkerPool(study, min(self.workers, len(indices)),
                          fast=len(indices) >= compiled.MANY)
        try:
            yield from pool.run(study, None, indices, recordings)
        finally:  # also on Ctrl-C or an error
            pool.close()


BACKENDS.register("local")(LocalBackend)


# -- ray: a local instance, or an existing cluster ----------------------------------------
class _RayWorker:
    """A Ray actor holding the study, so each chunk sends only its indices."""

    def __init__(self, study: Study) -> None:
        self.study = study
        compiled.enable()  # an actor runs chunk after chunk

    def run(self, indices: list[int], recordings: Path | None) -> ChunkResult:
        return run_chunk(self.study, indices, recordings)


class RayBackend:
    """``ray.init(address=...)`` for an existing cluster, else a local instance of ``workers``
    CPUs; one actor per CPU (as many as the cluster has, with an address). A chunk whose actor
    is lost is sent again one scenario at a time to fresh actors; a scenario whose actor is
    lost twice is a failed row."""

    name = "ray"

    def __init__(self, workers: int, address: str | None = None) -> None:
        try:
            import ray  # noqa: F401
        except ImportError:
            raise InputError("the ray backend needs the optional extra: "
                             "pip install 'astralis-des[ray]'", key="backend") from None
        self.workers = max(1, workers)
        self.address = address
        self._started = False  # an instance of ours kept by hold() until close()

    def run(self, study: Study, chunks: Sequence[list[int]],
            recordings: Path | None) -> Generator[ChunkResult, None, None]:
        import ray

        started = not ray.is_initialized()
        if started:
            self._connect()
        actors: list[Any] = []
        try:
            if self.address is not None:
                self.workers = max(1, int(ray.cluster_resources().get("CPU", self.workers)))
            yield from _RayRun(study, ray.put(study), recordings, actors).run(
                chunks, min(self.workers, len(chunks)))
        finally:
            for a in actors:
                ray.kill(a)
            if started:
                ray.shutdown()

    def _connect(self) -> None:
        """A local instance, or the cluster at ``address``: one line when it cannot be had
        (a cluster with token authentication asks for ``RAY_AUTH_MODE=token`` and the
        token)."""
        import ray

        options: dict[str, Any] = {"include_dashboard": False, "logging_level": "ERROR",
                                   "log_to_driver": False}
        if self.address is None:
            options["num_cpus"] = self.workers
        try:
            with quiet_c_output(2):  # Ray's core logs each retry of a refused connection
                ray.init(address=self.address, **options)
        except (ConnectionError, RuntimeError, ValueError) as exc:
            reason = " ".join(str(exc).split())[:200]
            raise InputError(
                f"cannot use the Ray cluster at {self.address or 'this machine'} ({reason}); "
                "a cluster with token authentication needs RAY_AUTH_MODE=token and its token "
                "in RAY_AUTH_TOKEN or RAY_AUTH_TOKEN_PATH (docs/studies.md)",
                key="address") from None

    def hold(self, base: Study) -> None:
        """One Ray instance (or connection) for the runs that follow, until :meth:`close`
        (each run starts its actors): a tune's trials or a falsify's batches do not start
        Ray each time."""
        import ray

        if not ray.is_initialized():
            self._connect()
            self._started = True

    def close(self) -> None:
        if self._started:
            import ray

            ray.shutdown()
            self._started = False


class _RayRun:
    """One study's chunks on actors; a lost actor's chunk is split and sent again."""

    def __init__(self, study: Study, ref: Any, recordings: Path | None,
                 actors: list[Any]) -> None:
        import ray

        self.study, self.ref, self.recordings, self.actors = study, ref, recordings, actors
        self.actor: Any = ray.remote(num_cpus=1, max_restarts=0)(_RayWorker)

    def run(self, chunks: Sequence[list[int]], width: int
            ) -> Generator[ChunkResult, None, None]:
        import ray
        from ray.exceptions import RayActorError, WorkerCrashedError

        todo = [(list(c), 0) for c in chunks]  # (indices, times their actor was lost)
        running: dict[Any, tuple[Any, list[int], int]] = {}  # future: (actor, chunk, lost)
        free = [self._new() for _ in range(width)]
        while todo or running:
            while todo and free:
                actor = free.pop()
                indices, lost = todo.pop(0)
                running[actor.run.remote(indices, self.recordings)] = (actor, indices, lost)
            done, _ = ray.wait(list(running), num_returns=1)
            actor, indices, lost = running.pop(done[0])
            try:
                result: ChunkResult = ray.get(done[0])
            except (RayActorError, WorkerCrashedError) as exc:
                reason = f"Ray actor lost ({type(exc).__name__})"
                log.warning("scenarios %s: %s; running them again", indices, reason)
                free.append(self._new())
                if lost == 0:  # again, a scenario each, so one that kills its actor is found
                    todo[:0] = [([i], 1) for i in indices]
                else:
                    yield failed_scenario(self.study, indices[0], f"{reason} (twice)")
                continue
            free.append(actor)
            yield result

    def _new(self) -> Any:
        actor = self.actor.remote(self.ref)
        self.actors.append(actor)
        return actor


BACKENDS.register("ray")(RayBackend)
