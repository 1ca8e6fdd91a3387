"""The registries a study file names (``evaluate:``, ``report:``), held apart from what fills
them so that the study's schema can check a name without importing the evaluations and
reports (which import the schema). Each is filled by its ``plugins`` on first use."""

from __future__ import annotations

from typing import Any

from astralis_des.registry import Registry

EVALUATIONS: Registry[str, Any] = Registry(
    "study evaluation",
    plugins=("astralis_des.studies.eval_assignment", "astralis_des.studies.eval_mission",
             "astralis_des.studies.falsify_eval"))
REPORTS: Registry[str, Any] = Registry(
    "study report", plugins=("astralis_des.studies.reports", "astralis_des.studies.table5"))
