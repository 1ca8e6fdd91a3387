"""Multi-agent environments over the mission kernel (PettingZoo's AEC and parallel APIs).

    pip install 'astralis-des[env]'

An agent acts when its macro-action (a Table I search of a room, a hold) ends; the simulated
time in between costs nothing. See :mod:`astralis_des.env.layout` for the actions,
:mod:`astralis_des.env.observe` for the observations and :mod:`astralis_des.env.rewards` for
the default reward.
"""

from __future__ import annotations

try:
    import gymnasium  # noqa: F401
    import pettingzoo  # noqa: F401
except ImportError as exc:  # pragma: no cover - the extra is not installed
    raise ImportError("astralis_des.env needs PettingZoo and Gymnasium: "
                      "pip install 'astralis-des[env]'") from exc

from astralis_des.env.aec import MissionEnv
from astralis_des.env.layout import CONTINUE, HOLD, SEARCHES, WAIT, Layout
from astralis_des.env.parallel import ParallelMissionEnv
from astralis_des.env.policies import mixed_policy, random_policy
from astralis_des.env.rewards import Progress, RewardWeights

__all__ = ["CONTINUE", "HOLD", "SEARCHES", "WAIT", "Layout", "MissionEnv",
           "ParallelMissionEnv", "Progress", "RewardWeights", "mixed_policy",
           "random_policy"]
