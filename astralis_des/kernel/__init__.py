"""The event kernel: tasks, task handlers, robots, the event log and the simulation."""
