"""A robot's task handler: a FIFO :class:`simpy.Store` of tasks and one worker process."""

from __future__ import annotations

from collections.abc import Callable, Generator
from typing import Any, cast

import simpy

from astralis_des.kernel.tasks import ActionResult, Stop, Task, TaskStatus

ActionRunner = Callable[[Task], Generator[simpy.Event, Any, ActionResult]]


class TaskHandler:
    """Runs one robot's tasks in first-in, first-out order.

    ``submit`` returns an event that succeeds with the task's :class:`ActionResult`, whether it
    ran, failed, was cancelled while queued or preempted while running.
    """

    def __init__(self, env: simpy.Environment, run: ActionRunner,
                 on_change: Callable[[Task, ActionResult | None], None] | None = None) -> None:
        self.env = env
        self.queue: simpy.Store = simpy.Store(env)
        self.current: Task | None = None
        self._run = run
        self._active: simpy.Process | None = None
        self._done: dict[int, simpy.Event] = {}
        self._on_change = on_change
        self._get: simpy.Event | None = None
        self._dropped: set[int] = set()
        self._stopping: Task | None = None
        self.worker = env.process(self._work())

    def _taken(self) -> Task | None:
        """The task the worker has taken from the queue but not yet started (same instant)."""
        get = self._get
        return cast(Task, get.value) if get is not None and get.triggered else None

    @property
    def queued(self) -> list[Task]:
        """Tasks waiting, in the order they will run."""
        taken = self._taken()
        ahead = [taken] if taken is not None and taken.id not in self._dropped else []
        return ahead + list(self.queue.items)

    @property
    def waiting(self) -> bool:
        """Whether any task is waiting (``queued`` is not empty), without listing them."""
        if self.queue.items:
            return True
        taken = self._taken()
        return taken is not None and taken.id not in self._dropped

    def submit(self, task: Task, *, front: bool = False) -> simpy.Event:
        done = self.env.event()
        self._done[task.id] = done
        self.queue.put(task)
        if front:  # the put above is served on the next step, so reordering now is safe
            self.queue.items.remove(task)
            self.queue.items.insert(0, task)
        return done

    def done_event(self, task_id: int) -> simpy.Event:
        return self._done[task_id]

    def cancel(self, task_id: int | None = None, reason: str = "cancelled") -> list[Task]:
        """Cancel one task (queued or running) or, with no id, all of them."""
        hit = [t for t in self.queued if task_id in (None, t.id)]
        for task in hit:
            self._drop(task, TaskStatus.CANCELLED, reason)
        if self.current is not None and task_id in (None, self.current.id):
            hit.append(self.current)
            self.stop_current(Stop(TaskStatus.CANCELLED, reason))
        return hit

    def fail(self, reason: str) -> None:
        """The robot broke: its running (or starting) task fails, the queued ones are cancelled."""
        taken = self._taken()
        if taken is not None:
            self._drop(taken, TaskStatus.FAILED, reason)
        for task in list(self.queue.items):
            self._drop(task, TaskStatus.CANCELLED, reason)
        self.stop_current(Stop(TaskStatus.FAILED, reason))

    def preempt(self, task: Task, reason: str = "preempted") -> simpy.Event:
        """Put ``task`` first and interrupt the running task, which ends ``preempted``."""
        taken = self._taken()
        if taken is not None:  # about to start: it is preempted before its first step
            self._drop(taken, TaskStatus.PREEMPTED, reason)
        done = self.submit(task, front=True)
        self.stop_current(Stop(TaskStatus.PREEMPTED, reason))
        return done

    def stop_current(self, cause: Stop) -> None:
        """Interrupt the running task; not when it is the one asking (it ends by itself)."""
        active = self._active
        if active is not None and active.is_alive and active is not self.env.active_process:
            active.interrupt(cause)
            self._stopping = self.current  # it ends when the interrupt lands (same instant)

    def view(self) -> tuple[Task | None, list[Task]]:
        """``(running, queued)`` as a user should see them: a task already told to stop (it
        ends at this instant, when the interrupt lands) is gone, and the task preempting it
        runs."""
        current, queued = self.current, self.queued
        if current is not None and current is self._stopping:
            return (queued[0], queued[1:]) if queued else (None, queued)
        return current, queued

    def _drop(self, task: Task, status: TaskStatus, reason: str) -> None:
        """End a task that has not started: take it out of the queue, or skip it if taken."""
        if task in self.queue.items:
            self.queue.items.remove(task)
        else:
            self._dropped.add(task.id)
        self._settle(task, ActionResult(status, reason, self.env.now, self.env.now))

    def _work(self) -> Generator[simpy.Event, Any, None]:
        while True:
            self._get = self.queue.get()
            task = yield self._get
            self._get = None
            if task.id in self._dropped:
                self._dropped.discard(task.id)
                continue
            self.current = task
            # The action's first step always precedes any interrupt sent from here on
            # (SimPy runs the process's initialisation first), so the action sees it.
            self._active = self.env.process(self._run(task))
            if self._on_change is not None:
                self._on_change(task, None)
            result = yield self._active
            self._active = None
            self.current = self._stopping = None
            self._settle(task, result)

    def _settle(self, task: Task, result: ActionResult) -> None:
        if self._on_change is not None:
            self._on_change(task, result)
        self._done[task.id].succeed(result)
