"""Table II's avatar attributes agree with each other (issue 24): only a sitting avatar is
tied to a chair; 35 of 300 seeds drew a tied avatar that patrolled, lay or stood."""

from __future__ import annotations

import numpy as np
import pytest

from astralis_des.mission.loader import Mission
from astralis_des.simulation import Simulation
from astralis_des.world.catalogue import agree
from astralis_des.world.clutter import place_room


def test_no_target_is_tied_to_a_chair_unless_it_sits(urban_search: Mission) -> None:
    drawn = [Simulation(urban_search.with_changes(seed=s)).target.avatar for s in range(300)]
    assert not [a for a in drawn if a["tied_to_chair"] and a["activity"] != "sitting"]
    assert [a for a in drawn if a["tied_to_chair"]]  # sitting ones still are
    assert {a["activity"] for a in drawn} == {"sitting", "laying", "patrolling", "idle"}


def test_no_bystander_is_tied_to_a_chair_unless_it_sits(urban_search: Mission) -> None:
    world = urban_search.world
    avatars = [dict(p.attributes) for seed in range(40) for rid in sorted(world.rooms)[:6]
               for p in place_room(world, rid, 1.0, np.random.default_rng(seed),
                                   urban_search.clutter_catalogue()).placed
               if p.kind == "avatar"]
    assert len(avatars) > 100
    assert not [a for a in avatars if a["tied_to_chair"] and a["activity"] != "sitting"]


def test_what_a_file_gives_stands() -> None:
    assert agree({"activity": "patrolling", "tied_to_chair": True}, frozenset({"tied_to_chair"})
                 ) == {"activity": "sitting", "tied_to_chair": True}
    assert agree({"activity": "laying", "tied_to_chair": True}, frozenset({"activity"})
                 ) == {"activity": "laying", "tied_to_chair": False}


def test_a_file_that_ties_a_patrolling_target_is_refused(urban_search: Mission) -> None:
    from astralis_des.errors import InputError

    with pytest.raises(InputError, match="only a sitting avatar is tied to a chair"):
        urban_search.with_changes(target={"room": "A.1.1.1", "avatar": {
            "activity": "patrolling", "tied_to_chair": True}})


def test_sitting_bystanders_sit_on_chairs(urban_search: Mission) -> None:
    """Issue 24: every sitting bystander is on a chair of its room (one it found free, or one
    brought for it), one avatar a chair; over 300 furnished rooms at full messiness."""
    world = urban_search.world
    sitting = 0
    for seed in range(100):
        for room in ("A.1.1.1", "A.1.1.2", "A.2.2.3"):
            clutter = place_room(world, room, 1.0, np.random.default_rng(seed))
            chairs = [p for p in clutter.placed if p.kind == "chair"]
            seated = [p for p in clutter.placed if p.kind == "avatar"
                      and dict(p.attributes)["activity"] == "sitting"]
            taken = []
            for avatar in seated:
                under = [c for c in chairs if np.allclose(c.center[:2], avatar.center[:2])]
                assert len(under) == 1, (seed, room, avatar)
                taken.append(id(under[0]))
                assert avatar.box.lo[2] == pytest.approx(world.floor_below(avatar.center))
            assert len(taken) == len(set(taken))  # one avatar a chair
            sitting += len(seated)
    assert sitting > 50


def test_open_air_areas_get_bystanders_but_no_furniture_unless_asked() -> None:
    """Issue 24: an imported world's search areas were furnished like offices (chairs on the
    open ground). Out in the open only bystanders are placed, unless the mission asks for
    furniture with scene.furnish_outdoors."""
    from pathlib import Path

    from astralis_des import load_mission

    mission = load_mission(Path(__file__).resolve().parents[1] / "missions" /
                           "autzen_recon.yaml")
    rooms = {rid: {"messiness": 1.0} for rid in ("S.1.1.1", "S.1.1.2", "S.1.2.1", "S.1.2.2")}
    plain = Simulation(mission.with_changes(rooms={"set": rooms}))
    plain.scene.furnish(rooms)
    kinds = {p.kind for rid in rooms for p in plain.scene.clutter(rid).placed}
    assert kinds == {"avatar"}
    asked = Simulation(mission.with_changes(rooms={"set": rooms},
                                            scene={"furnish_outdoors": True}))
    asked.scene.furnish(rooms)
    kinds = {p.kind for rid in rooms for p in asked.scene.clutter(rid).placed}
    assert "avatar" in kinds and kinds - {"avatar"}
