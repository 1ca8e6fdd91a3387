"""``astralis_des.yamlio.load_yaml``: safe reading that remembers the line of every key."""

from __future__ import annotations

import contextlib
import textwrap
import tracemalloc
from pathlib import Path

import pytest

from astralis_des.errors import InputError
from astralis_des.yamlio import format_path, load_yaml

DOC = textwrap.dedent("""\
    # a comment
    name: demo
    team:
      - id: a
        speed: 1.5
      - id: b
        kind: uav

        speed: 3
      - {id: c, speed: 4}
    nested:
      deeper:
        list: [x, y]
    """)


def write(tmp_path: Path, text: str, name: str = "doc.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_data(tmp_path: Path) -> None:
    doc = load_yaml(write(tmp_path, DOC))
    assert doc.data == {
        "name": "demo",
        "team": [{"id": "a", "speed": 1.5}, {"id": "b", "kind": "uav", "speed": 3},
                 {"id": "c", "speed": 4}],
        "nested": {"deeper": {"list": ["x", "y"]}},
    }
    assert doc.file == tmp_path / "doc.yaml"


@pytest.mark.parametrize(("path", "line"), [
    ((), 2),
    (("name",), 2),
    (("team",), 3),
    (("team", 0), 4),
    (("team", 0, "id"), 4),
    (("team", 0, "speed"), 5),
    (("team", 1), 6),
    (("team", 1, "kind"), 7),
    (("team", 1, "speed"), 9),
    (("team", 2), 10),
    (("team", 2, "speed"), 10),
    (("nested", "deeper"), 12),
    (("nested", "deeper", "list"), 13),
    (("nested", "deeper", "list", 1), 13),
])
def test_line_of(tmp_path: Path, path: tuple[str | int, ...], line: int) -> None:
    assert load_yaml(write(tmp_path, DOC)).line_of(path) == line


def test_line_of_falls_back_to_nearest_ancestor(tmp_path: Path) -> None:
    doc = load_yaml(write(tmp_path, DOC))
    assert doc.line_of(("team", 1, "height")) == 6  # no such key: the item's line
    assert doc.line_of(("team", 7, "speed")) == 3  # no such item: the list's line
    assert doc.line_of(("nowhere",)) == 2  # the document's first line


def test_error_names_file_line_and_key(tmp_path: Path) -> None:
    path = write(tmp_path, DOC)
    error = load_yaml(path).error(("team", 1, "speed"), "too  fast\n really")
    assert isinstance(error, InputError)
    assert (error.file, error.line, error.key) == (str(path), 9, "team[1].speed")
    assert str(error) == f"{path}:9: team[1].speed: too fast really"


def test_format_path() -> None:
    assert format_path(("team", 1, "speed")) == "team[1].speed"
    assert format_path(("rooms", "set", "A.1.1.1")) == "rooms.set.A.1.1.1"
    assert format_path(()) == ""


def test_scalars_are_typed_safely(tmp_path: Path) -> None:
    doc = load_yaml(write(tmp_path, "a: 1\nb: 1.5\nc: true\nd: ~\ne: '1'\n1: int key\n"))
    assert doc.data == {"a": 1, "b": 1.5, "c": True, "d": None, "e": "1", "1": "int key"}


def test_duplicate_key_names_both_lines(tmp_path: Path) -> None:
    path = write(tmp_path, "name: demo\nseed: 1\nteam: []\nseed: 2\n")
    with pytest.raises(InputError) as exc:
        load_yaml(path)
    error = exc.value
    assert (error.file, error.line, error.key) == (str(path), 4, "seed")
    assert "duplicate key 'seed'" in error.message
    assert "line 2" in error.message
    assert str(error).startswith(f"{path}:4: seed: ")


def test_nested_duplicate_key(tmp_path: Path) -> None:
    path = write(tmp_path, "team:\n  - id: a\n    speed: 1\n    speed: 2\n")
    with pytest.raises(InputError) as exc:
        load_yaml(path)
    assert (exc.value.line, exc.value.key) == (4, "team[0].speed")
    assert "line 3" in exc.value.message


def test_duplicate_key_in_flow_mapping(tmp_path: Path) -> None:
    with pytest.raises(InputError) as exc:
        load_yaml(write(tmp_path, "a: 0\nb: {x: 1, x: 2}\n"))
    assert (exc.value.line, exc.value.key) == (2, "b.x")


def test_same_key_in_different_mappings_is_fine(tmp_path: Path) -> None:
    doc = load_yaml(write(tmp_path, "- {id: a}\n- {id: b}\n"))
    assert doc.data == [{"id": "a"}, {"id": "b"}]


def test_python_scalar_tag_is_refused(tmp_path: Path) -> None:
    path = write(tmp_path, "a: 1\nb: !!python/name:os.system x\n")
    with pytest.raises(InputError) as exc:
        load_yaml(path)
    assert exc.value.file == str(path)
    assert exc.value.line == 2
    assert "python/name:os.system" in exc.value.message


def test_python_object_tag_never_runs_code(tmp_path: Path) -> None:
    marker = tmp_path / "pwned"
    path = write(tmp_path,
                 f"a: !!python/object/apply:os.system ['touch {marker}']\n"
                 f"b: !!python/object/new:pathlib.Path ['{marker}']\n")
    with contextlib.suppress(InputError):
        load_yaml(path)
    assert not marker.exists()


@pytest.mark.parametrize("text", [
    "a: !!python/object:collections.OrderedDict {x: 1}\n",
    "a: !!python/object/apply:os.system [echo hi]\n",
    "!!python/object:os.system\nname: x\n",
])
def test_python_object_tag_is_refused(tmp_path: Path, text: str) -> None:
    with pytest.raises(InputError) as exc:
        load_yaml(write(tmp_path, text))
    assert "python/object" in exc.value.message
    assert exc.value.line is not None


@pytest.mark.parametrize("text", ["", "\n\n", "# only a comment\n"])
def test_empty_file(tmp_path: Path, text: str) -> None:
    path = write(tmp_path, text)
    with pytest.raises(InputError) as exc:
        load_yaml(path)
    assert exc.value.file == str(path)
    assert "empty" in exc.value.message
    assert str(exc.value).startswith(str(path))


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "nope.yaml"
    with pytest.raises(InputError) as exc:
        load_yaml(path)
    assert str(exc.value) == f"{path}: no such file"


def test_directory_and_binary_file_are_input_errors(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="cannot read"):
        load_yaml(tmp_path)
    binary = tmp_path / "bin.yaml"
    binary.write_bytes(b"a: \xff\xfe\n")
    with pytest.raises(InputError, match="cannot read"):
        load_yaml(binary)


def test_syntax_error_has_a_line(tmp_path: Path) -> None:
    with pytest.raises(InputError) as exc:
        load_yaml(write(tmp_path, "a: 1\nb: 2: 3\nc: 4\n"))
    assert exc.value.line == 2
    assert "YAML syntax error" in exc.value.message


def test_several_documents_are_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError) as exc:
        load_yaml(write(tmp_path, "a: 1\n---\nb: 2\n"))
    assert exc.value.line == 2


def test_non_scalar_key_is_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError) as exc:
        load_yaml(write(tmp_path, "a: 1\n? [x, y]\n: 2\n"))
    assert exc.value.line == 2
    assert "key" in exc.value.message


def test_aliases_are_expanded(tmp_path: Path) -> None:
    doc = load_yaml(write(tmp_path, "base: &b {speed: 2}\nother: *b\n"))
    assert doc.data == {"base": {"speed": 2}, "other": {"speed": 2}}


def test_recursive_alias_is_an_input_error(tmp_path: Path) -> None:
    with pytest.raises(InputError) as exc:
        load_yaml(write(tmp_path, "a: 1\nb: &x [1, *x]\n"))
    assert exc.value.line == 2


def test_alias_bomb_is_cheap_or_refused(tmp_path: Path) -> None:
    # 10**4 leaves here; every extra line multiplies the cost of load_yaml by ten.
    lines = ["l0: &l0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * 10) + "]" for i in range(1, 5)]
    path = write(tmp_path, "\n".join(lines) + "\n")
    tracemalloc.start()
    try:
        load_yaml(path)
    except InputError:
        return
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    assert peak < 4_000_000, f"peak {peak / 1e6:.1f} MB to read a {path.stat().st_size} B file"
