"""Indoor analysis (issue 42) on a building model that is not ours: the first floor of the AWS
RoboMaker hospital world (MIT-0; ``tests/data/interiors/aws_hospital/``: its walls, floor and
ceiling as an OBJ, the plan's truth read from the model in ``plan.yaml``; see its SOURCE.md),
sampled on its faces every 5 cm (about 2.3 million points).

What holds: one storey, 0 to 3 m; the 18 rooms with 0.93 m doorways (offices, side rooms,
washrooms) each found with an IoU of at least 0.95, and each doorway within 0.1 m and 0.1 m of
width. What does not: the wards and halls behind the 1.5 m bed doorways and the interior
windows (3.6 m openings over 0.96 m sills, frames without glass) are one space with the
corridor, since ``DOOR_MAX`` is 1.4 m and a sill is as low as furniture (``door_max`` 1.7
parts the rooms behind bed doorways alone); the two stores by the stairs take in the stairs'
landing (the truth leaves stairs out).
"""

from __future__ import annotations

import numpy as np
import pytest
from interior_models import INTERIORS, PlanScore, load_obj, load_plan, sample_faces, score_plan

from astralis_des.importers.indoor import Interior, find_interior

SPACING = 0.05  # m between points on a face
SMALL_DOOR_ROOMS = ["w_office_s", "w_office_n", "nw_room", "w_wc_s", "w_wc_n", "c_room_sw",
                    "c_room_mw", "c_room_nw", "c_room_se", "c_room_me", "c_room_ne", "ne_room",
                    "e_wc_s", "e_wc_n", "e_office_s", "e_office_n"]
WIDE = ["sw_room", "se_hall"]  # behind 1.5 m doorways only
WARDS = ["w_ward_s", "w_ward_n", "e_ward_s", "e_ward_n"]  # 1.5 m doorways and open windows


@pytest.fixture(scope="module")
def cloud() -> np.ndarray:
    vertices, parts = load_obj(INTERIORS / "aws_hospital" / "hospital_floor1.obj")
    return sample_faces(vertices, np.concatenate(list(parts.values())), SPACING, seed=0)


@pytest.fixture(scope="module")
def found(cloud: np.ndarray) -> tuple[Interior, PlanScore]:
    interior = find_interior(cloud)
    return interior, score_plan(load_plan("aws_hospital"), interior)


def test_one_storey(found: tuple[Interior, PlanScore]) -> None:
    """The floor at 0 m, the ceiling at 3 m; walls along the axes."""
    interior, _ = found
    assert [(s.z, s.ceiling) for s in interior.storeys] == [(0.0, 3.0)]
    assert interior.heading == 0.0


def test_rooms_with_doorways_are_found(found: tuple[Interior, PlanScore]) -> None:
    """Each room whose doorways are 0.93 m is a found room of its own (IoU >= 0.95, one found
    room each); the stores by the stairs are found with their landings (IoU about 0.53)."""
    _, score = found
    assert min(score.iou[r] for r in SMALL_DOOR_ROOMS) >= 0.95
    assert len({score.matched[r] for r in SMALL_DOOR_ROOMS}) == len(SMALL_DOOR_ROOMS)
    assert all(0.45 <= score.iou[r] <= 0.65 for r in ("nw_store", "ne_store"))


def test_doorways_are_found(found: tuple[Interior, PlanScore]) -> None:
    """The 18 doorways of 0.93 m: a found door within 0.1 m of each, 0.1 m of its width, in
    a wall across the same axis; 18 found doors, no more."""
    interior, score = found
    plan = load_plan("aws_hospital")
    small = [k for k, d in enumerate(plan["doors"]) if d["frame"] == "small"]
    assert len(small) == 18
    assert all(score.door_error[k][0] <= 0.1 and score.door_error[k][1] <= 0.1
               and score.door_error[k][2] for k in small)
    assert len(interior.doors) == 18


def test_wide_doorways_part_rooms_with_a_wider_door_max(cloud: np.ndarray) -> None:
    """With ``door_max`` 1.7 m the rooms behind 1.5 m doorways are parted too (IoU >= 0.95),
    and the washrooms, 1.36 m wide, narrower than such a door, are still rooms of their own
    (parted at their 0.93 m doors: ``rooms.NARROW``)."""
    score = score_plan(load_plan("aws_hospital"), find_interior(cloud, door_max=1.7))
    assert min(score.iou[r] for r in WIDE) >= 0.95
    assert min(score.iou[r] for r in ("w_wc_s", "w_wc_n", "e_wc_s", "e_wc_n")) >= 0.9


@pytest.mark.xfail(strict=True, reason="1.5 m bed doorways are wider than DOOR_MAX (1.4 m) "
                   "and the interior windows' 0.96 m sills are as low as furniture: the wards, "
                   "the south-west room and the south-east hall join the corridor")
def test_wards_and_halls_are_rooms(found: tuple[Interior, PlanScore]) -> None:
    _, score = found
    assert min(score.iou[r] for r in WIDE + WARDS + ["corridor"]) >= 0.8
