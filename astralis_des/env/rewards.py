"""What an agent is rewarded for between two of its decisions.

The default, :class:`RewardWeights`, is a team reward (every robot gets it) less the agent's own
refused actions::

    r = found * [the target was found]
        - time * seconds elapsed
        - human_risk * seconds the person spent searching rooms of risk >= the mission's
          high_risk threshold
        - ugv_clutter * seconds the UGV spent searching rooms of messiness >= high_messiness
        - failure * tasks of the team that failed
        - refused * this agent's actions the environment refused

The exposure terms are the metrics of the paper's Table V (``human_high_risk_s``,
``ugv_high_mess_s``), counted when each search ends. Any callable ``(progress, agent) ->
float`` can replace it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Progress:
    """What happened in the mission between two decision times."""

    dt: float  # simulated seconds
    found: bool  # the target was found in this interval
    human_risk_s: float  # the person searching high-risk rooms (searches that ended)
    ugv_clutter_s: float  # the UGV searching high-messiness rooms (searches that ended)
    failed: dict[str, int] = field(default_factory=dict)  # failed tasks, by robot
    refused: dict[str, int] = field(default_factory=dict)  # refused actions, by agent
    searched: int = 0  # rooms newly counted as searched
    outcome: str | None = None  # why the mission ended, if it did


RewardFn = Callable[[Progress, str], float]


@dataclass(frozen=True)
class RewardWeights:
    """The default reward (see the module's docstring); weights per unit."""

    found: float = 100.0
    time: float = 0.1
    human_risk: float = 0.5
    ugv_clutter: float = 0.5
    failure: float = 5.0
    refused: float = 1.0

    def __call__(self, progress: Progress, agent: str) -> float:
        return float(self.found * progress.found - self.time * progress.dt
                     - self.human_risk * progress.human_risk_s
                     - self.ugv_clutter * progress.ugv_clutter_s
                     - self.failure * sum(progress.failed.values())
                     - self.refused * progress.refused.get(agent, 0))
