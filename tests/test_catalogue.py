"""The clutter catalogue file: the packaged default, and errors naming file, line and key."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from astralis_des.errors import InputError
from astralis_des.world.catalogue import (
    ITEM_KINDS,
    Catalogue,
    avatar_size,
    default_catalogue,
    load_catalogue,
)

CHAIR = {"size_min": [0.45, 0.45, 0.8], "size_max": [0.55, 0.55, 1.0], "per_10m2_at_full": 2.0}


def write(tmp_path: Path, text: str, name: str = "clutter.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_default_catalogue_lists_the_five_types_and_table_ii() -> None:
    """The packaged catalogue has every item type, the default keep-out and passage."""
    catalogue = default_catalogue()
    assert tuple(catalogue.items.present()) == ITEM_KINDS
    assert set(ITEM_KINDS) == {"chair", "cabinet", "table", "potted_plant", "computer_desk"}
    assert catalogue.door_keepout == (1.2, 1.4)
    assert catalogue.passage == 0.7
    walls = {k for k, item in catalogue.items.present().items() if item.against_wall}
    assert walls == {"cabinet", "computer_desk"}
    assert catalogue.avatars.attributes.activity == ("sitting", "laying", "patrolling", "idle")
    assert catalogue.avatars.attributes.tied_to_chair == (True, False)


def test_default_sizes_are_plausible() -> None:
    """A chair is about half a metre wide; a cabinet is taller than a person's shoulder."""
    items = default_catalogue().items.present()
    assert items["chair"].size_min == (0.45, 0.45, 0.8)
    assert items["cabinet"].size_max == (1.2, 0.5, 2.0)
    assert items["computer_desk"].size_min[2] == 0.72


def test_avatar_sizes_follow_activity_and_height() -> None:
    """Standing avatars are 0.5 x 0.5 m at their height; sitting 1.3 m; laying 1.8 x 0.6."""
    assert avatar_size("idle", "tall") == (0.5, 0.5, 1.85)
    assert avatar_size("patrolling", "short") == (0.5, 0.5, 1.58)
    assert avatar_size("sitting", "tall") == (0.5, 0.5, 1.3)
    assert avatar_size("laying", "medium") == (1.8, 0.6, 0.35)


def test_unknown_type_gets_did_you_mean(tmp_path: Path) -> None:
    """A misspelt type is refused on one line naming file, line, key and the likely type."""
    path = write(tmp_path, "items:\n  chiar:\n    size_min: [0.4, 0.4, 0.8]\n")
    with pytest.raises(InputError) as info:
        load_catalogue(path)
    message = str(info.value)
    assert "\n" not in message
    assert message == f"{path}:2: items.chiar: unknown key 'chiar'; did you mean 'chair'?"


def test_attribute_outside_table_ii_names_the_key(tmp_path: Path) -> None:
    """An activity not in Table II is refused, naming the key and listing valid values."""
    text = ("items: {}\navatars:\n  attributes:\n"
            "    activity: [sitting, dancing]\n")
    with pytest.raises(InputError) as info:
        load_catalogue(write(tmp_path, text))
    assert info.value.key == "avatars.attributes.activity[1]"
    assert info.value.line == 4
    assert "'patrolling'" in info.value.message and "'dancing'" in info.value.message


def test_colour_outside_table_ii_is_refused(tmp_path: Path) -> None:
    """A colour outside yellow/red/purple/blue is refused with its key."""
    text = "items: {}\navatars:\n  attributes:\n    color: [green]\n"
    with pytest.raises(InputError, match=r"avatars\.attributes\.color\[0\]: .*'green'"):
        load_catalogue(write(tmp_path, text))


def test_json_catalogue_loads(tmp_path: Path) -> None:
    """A catalogue written as JSON loads like YAML."""
    doc = {"items": {"chair": CHAIR}, "passage": 0.8, "door_keepout": [1.0, 1.2],
           "avatars": {"per_room_at_full": 0, "attributes": {"gender": ["female"]}}}
    catalogue = load_catalogue(write(tmp_path, json.dumps(doc, indent=2), "clutter.json"))
    assert list(catalogue.items.present()) == ["chair"]
    assert catalogue.passage == 0.8
    assert catalogue.avatars.attributes.gender == ("female",)


def test_size_min_above_size_max_is_refused(tmp_path: Path) -> None:
    """size_min larger than size_max in any axis is refused at size_max, naming the axis."""
    text = ("items:\n  table:\n    size_min: [1.8, 0.7, 0.72]\n    size_max: [1.2, 0.9, 0.76]\n"
            "    per_10m2_at_full: 0.4\n")
    with pytest.raises(InputError) as info:
        load_catalogue(write(tmp_path, text))
    assert info.value.key == "items.table.size_max"
    assert info.value.line == 4
    assert info.value.message == "size_max is below size_min (w 1.8 > 1.2)"


def test_catalogue_model_is_frozen_and_strict() -> None:
    """An unknown top-level key is refused even without a file."""
    with pytest.raises(ValueError, match="passages"):
        Catalogue.model_validate({"items": {}, "passages": 0.7})
