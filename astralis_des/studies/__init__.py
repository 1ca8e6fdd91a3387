"""Scheduling studies: a base mission, what each scenario draws, what varies, how many.

    from astralis_des.studies import load_study, run_study

    result = run_study(load_study("studies/table5.yaml"), workers=2)
    result.table            # pyarrow Table: one row per scenario and variant
    result.summary()        # per variant and metric, with 95% intervals
    result.write("out/table5")
"""

from __future__ import annotations

from astralis_des.studies.runner import StudyResult, run_scenario, run_study
from astralis_des.studies.spec import Study, Variant, load_study, make_study

__all__ = ["Study", "StudyResult", "Variant", "load_study", "make_study", "run_scenario",
           "run_study"]
