"""Tests for :class:`astralis_des.kernel.handler.TaskHandler`: one robot's FIFO of tasks.

The handler is driven directly with a bare ``simpy.Environment`` and a fake runner that waits
for the task's ``duration`` parameter. Like ``Simulation._run_action``, the runner turns an
interrupt whose cause is a :class:`Stop` into an :class:`ActionResult`.
"""

from __future__ import annotations

from collections.abc import Generator
from typing import Any

import pytest
import simpy

from astralis_des.kernel.handler import TaskHandler
from astralis_des.kernel.tasks import ActionResult, Stop, Task, TaskStatus


def task(task_id: int, duration: float) -> Task:
    return Task(task_id, "r1", "wait", params=(("duration", duration),))


class Bench:
    """A handler on a fresh environment, recording when each task's runner started."""

    def __init__(self) -> None:
        self.env = simpy.Environment()
        self.started: list[tuple[int, float]] = []
        self.changes: list[tuple[int, str | None, float]] = []
        self.handler = TaskHandler(self.env, self.run, self.on_change)

    def run(self, task: Task) -> Generator[simpy.Event, Any, ActionResult]:
        start = self.env.now
        self.started.append((task.id, start))
        try:
            yield self.env.timeout(task.param("duration", 1.0))
        except simpy.Interrupt as stop:
            cause = stop.cause
            assert isinstance(cause, Stop)
            return ActionResult(cause.status, cause.message, start, self.env.now)
        return ActionResult(TaskStatus.SUCCEEDED, "waited", start, self.env.now)

    def on_change(self, task: Task, result: ActionResult | None) -> None:
        status = None if result is None else result.status.value
        self.changes.append((task.id, status, self.env.now))

    def at(self, t: float, action: Any) -> None:
        """Call ``action()`` at simulated time ``t``."""

        def proc() -> Generator[simpy.Event, Any, None]:
            yield self.env.timeout(t - self.env.now)
            action()

        self.env.process(proc())


def span(done: simpy.Event) -> tuple[str, float, float]:
    result: ActionResult = done.value
    return result.status.value, result.start, result.end


def test_fifo_order() -> None:
    """Tasks submitted at t=0 with durations 5, 1, 3 end at 5, 6, 9 in submission order."""
    b = Bench()
    done = [b.handler.submit(task(i, d)) for i, d in ((1, 5), (2, 1), (3, 3))]
    b.env.run()
    assert [span(d) for d in done] == [
        ("succeeded", 0, 5), ("succeeded", 5, 6), ("succeeded", 6, 9)]
    assert b.started == [(1, 0), (2, 5), (3, 6)]
    assert b.env.now == 9


def test_done_event_is_the_submitted_one() -> None:
    """``done_event(id)`` returns the event that ``submit`` returned for that task."""
    b = Bench()
    done = b.handler.submit(task(7, 2))
    assert b.handler.done_event(7) is done
    b.env.run()
    assert span(b.handler.done_event(7)) == ("succeeded", 0, 2)


def test_on_change_sees_start_then_result() -> None:
    """The change hook is called with ``None`` when a task starts, then with its result."""
    b = Bench()
    b.handler.submit(task(1, 2))
    b.handler.submit(task(2, 1))
    b.env.run()
    assert b.changes == [(1, None, 0), (1, "succeeded", 2), (2, None, 2), (2, "succeeded", 3)]


def test_queued_lists_waiting_tasks_in_order() -> None:
    """``queued`` lists the waiting tasks in run order, without the running one."""
    b = Bench()
    t1, t2, t3 = task(1, 5), task(2, 1), task(3, 3)
    for t in (t1, t2, t3):
        b.handler.submit(t)
    assert b.handler.queued == [t1, t2, t3]  # nothing has run yet
    b.env.run(until=1)
    assert b.handler.current == t1
    assert b.handler.queued == [t2, t3]
    b.env.run(until=5.5)
    assert b.handler.current == t2
    assert b.handler.queued == [t3]
    b.env.run()
    assert b.handler.current is None
    assert b.handler.queued == []


def test_cancel_queued_task() -> None:
    """Cancelling a queued task settles it CANCELLED at once; the others still run."""
    b = Bench()
    t1, t2, t3 = task(1, 5), task(2, 1), task(3, 3)
    done = [b.handler.submit(t) for t in (t1, t2, t3)]
    hits: list[list[Task]] = []
    b.at(2, lambda: hits.append(b.handler.cancel(2)))
    b.env.run()
    assert hits == [[t2]]
    assert done[1].value.message == "cancelled"
    assert [span(d) for d in done] == [
        ("succeeded", 0, 5), ("cancelled", 2, 2), ("succeeded", 5, 8)]
    assert [tid for tid, _ in b.started] == [1, 3]


def test_cancel_with_a_reason() -> None:
    """The reason given to ``cancel`` is the cancelled task's result message."""
    b = Bench()
    b.handler.submit(task(1, 5))
    done = b.handler.submit(task(2, 1))
    b.at(1, lambda: b.handler.cancel(2, reason="operator said so"))
    b.env.run()
    assert done.value.status is TaskStatus.CANCELLED
    assert done.value.message == "operator said so"


def test_cancel_all() -> None:
    """``cancel()`` with no id cancels the running task at the cancel time and all queued."""
    b = Bench()
    t1, t2, t3 = task(1, 5), task(2, 1), task(3, 3)
    done = [b.handler.submit(t) for t in (t1, t2, t3)]
    hits: list[list[Task]] = []
    b.at(2, lambda: hits.append(b.handler.cancel()))
    b.env.run()
    assert sorted(t.id for t in hits[0]) == [1, 2, 3]
    assert [span(d) for d in done] == [
        ("cancelled", 0, 2), ("cancelled", 2, 2), ("cancelled", 2, 2)]
    assert b.started == [(1, 0)]
    assert b.handler.current is None
    assert b.handler.queued == []


def test_handler_keeps_working_after_cancel_all() -> None:
    """A task submitted after ``cancel()`` runs normally."""
    b = Bench()
    b.handler.submit(task(1, 5))
    b.handler.submit(task(2, 1))
    later: list[simpy.Event] = []
    b.at(2, lambda: b.handler.cancel())
    b.at(3, lambda: later.append(b.handler.submit(task(3, 4))))
    b.env.run()
    assert span(later[0]) == ("succeeded", 3, 7)


def test_preempt() -> None:
    """``preempt`` ends the running task PREEMPTED now and runs the new one before the queue."""
    b = Bench()
    t1, t2, t3, urgent = task(1, 5), task(2, 1), task(3, 3), task(9, 1)
    done = [b.handler.submit(t) for t in (t1, t2, t3)]
    pre: list[simpy.Event] = []
    b.at(2, lambda: pre.append(b.handler.preempt(urgent)))
    b.env.run()
    assert span(done[0]) == ("preempted", 0, 2)
    assert done[0].value.message == "preempted"
    assert span(pre[0]) == ("succeeded", 2, 3)
    assert span(done[1]) == ("succeeded", 3, 4)
    assert span(done[2]) == ("succeeded", 4, 7)
    assert b.started == [(1, 0), (9, 2), (2, 3), (3, 4)]


def test_preempt_when_idle_just_runs() -> None:
    """Preempting an idle handler runs the task; there is nothing to interrupt."""
    b = Bench()
    pre: list[simpy.Event] = []
    b.at(4, lambda: pre.append(b.handler.preempt(task(1, 2))))
    b.env.run()
    assert span(pre[0]) == ("succeeded", 4, 6)


def test_submit_front() -> None:
    """``submit(task, front=True)`` puts the task before the queued ones, not the running one."""
    b = Bench()
    t1, t2, t3, first = task(1, 5), task(2, 1), task(3, 3), task(4, 2)
    done = [b.handler.submit(t) for t in (t1, t2, t3)]
    front: list[simpy.Event] = []

    def jump() -> None:
        front.append(b.handler.submit(first, front=True))
        assert b.handler.queued == [first, t2, t3]

    b.at(1, jump)
    b.env.run()
    assert span(done[0]) == ("succeeded", 0, 5)  # not interrupted
    assert span(front[0]) == ("succeeded", 5, 7)
    assert span(done[1]) == ("succeeded", 7, 8)
    assert span(done[2]) == ("succeeded", 8, 11)


def test_submit_front_before_anything_ran() -> None:
    """At t=0, before the worker took anything, a front task runs first of all."""
    b = Bench()
    done = [b.handler.submit(task(1, 5)), b.handler.submit(task(2, 1))]
    first = b.handler.submit(task(3, 2), front=True)
    b.env.run()
    assert span(first) == ("succeeded", 0, 2)
    assert [span(d) for d in done] == [("succeeded", 2, 7), ("succeeded", 7, 8)]


@pytest.mark.parametrize("how", ["cancel", "preempt"])
def test_interrupt_at_the_instant_the_task_starts(how: str) -> None:
    """Stopping a task at the very instant it starts still gives it a result, of zero length."""
    b = Bench()
    done = b.handler.submit(task(1, 5))
    pre: list[simpy.Event] = []

    def stop() -> Generator[simpy.Event, Any, None]:
        yield b.env.timeout(0)  # the worker has started task 1; its runner has not waited yet
        assert b.handler.current is not None and b.handler.current.id == 1
        if how == "cancel":
            b.handler.cancel()
        else:
            pre.append(b.handler.preempt(task(2, 1)))

    b.env.process(stop())
    b.env.run()
    expected = "cancelled" if how == "cancel" else "preempted"
    assert span(done) == (expected, 0, 0)
    if how == "preempt":
        assert span(pre[0]) == ("succeeded", 0, 1)


def test_cancel_next_task_when_previous_finishes() -> None:
    """Cancelling the next task at the instant the previous one finishes cancels it."""
    b = Bench()
    t1, t2 = task(1, 5), task(2, 3)
    first = b.handler.submit(t1)
    second = b.handler.submit(t2)
    hits: list[list[Task]] = []

    def on_first_done() -> Generator[simpy.Event, Any, None]:
        yield first
        hits.append(b.handler.cancel(2))

    b.env.process(on_first_done())
    b.env.run()
    assert hits == [[t2]]
    assert span(second) == ("cancelled", 5, 5)


def test_cancel_all_at_time_zero() -> None:
    """``cancel()`` called at t=0 by a process started after ``submit`` cancels the task."""
    b = Bench()
    done = b.handler.submit(task(1, 5))
    hits: list[list[Task]] = []

    def cancel_now() -> Generator[simpy.Event, Any, None]:
        hits.append(b.handler.cancel())
        yield b.env.timeout(0)

    b.env.process(cancel_now())
    b.env.run()
    assert [t.id for t in hits[0]] == [1]
    assert span(done) == ("cancelled", 0, 0)


def test_waiting_says_whether_any_task_is_queued() -> None:
    """``waiting`` is ``bool(queued)`` at every step: tasks in the queue, one taken but not
    started yet, one dropped while taken, none."""
    bench = Bench()
    handler, env = bench.handler, bench.env
    seen = []
    for t in (task(1, 2.0), task(2, 1.0), task(3, 1.0)):
        handler.submit(t)
    handler.cancel(3)
    bench.at(2.5, lambda: (handler.submit(task(4, 1.0)), handler.cancel(4)))
    bench.at(5.0, lambda: (handler.submit(task(5, 1.0)), handler.cancel(5)))  # taken, dropped
    bench.at(6.0, lambda: handler.submit(task(6, 1.0)))  # taken, then started
    while env.peek() != float("inf"):
        assert handler.waiting == bool(handler.queued)
        seen.append(handler.waiting)
        env.step()
    assert handler.waiting is False and handler.queued == []
    assert True in seen and False in seen
