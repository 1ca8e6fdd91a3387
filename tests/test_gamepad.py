"""``astralis teleop --gamepad``: a virtual SDL joystick (no hardware) drives robots through
the API, and without a controller the command fails in one line."""

from __future__ import annotations

import contextlib
import io
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

sdl2 = pytest.importorskip("sdl2")

from astralis_des import Mission  # noqa: E402
from astralis_des.api import Client  # noqa: E402
from astralis_des.api.local import Background  # noqa: E402
from astralis_des.chat.gamepad import Gamepad, load_mapping, open_pad  # noqa: E402
from astralis_des.cli import main  # noqa: E402


@pytest.fixture()
def server(urban_search: Mission, tmp_path: Path) -> Iterator[Background]:
    manual = urban_search.with_changes(assignment={"auto": False, "search": ["A"]})
    background = Background(manual, running=False, out_dir=tmp_path / "out")
    background.start()
    yield background
    background.stop()


@pytest.fixture()
def virtual_pad() -> Iterator[Any]:
    """A virtual game controller (6 axes, 15 buttons), SDL's own, detached afterwards."""
    assert sdl2.SDL_Init(sdl2.SDL_INIT_JOYSTICK) == 0, sdl2.SDL_GetError()
    index = sdl2.SDL_JoystickAttachVirtual(sdl2.SDL_JOYSTICK_TYPE_GAMECONTROLLER, 6, 15, 0)
    assert index >= 0, sdl2.SDL_GetError()
    pad = open_pad(index)
    yield pad
    sdl2.SDL_JoystickClose(pad)
    sdl2.SDL_JoystickDetachVirtual(index)
    sdl2.SDL_QuitSubSystem(sdl2.SDL_INIT_JOYSTICK)


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_the_stick_walks_and_the_buttons_act(server: Background, virtual_pad: Any) -> None:
    """Leaning the left stick right steps the human operator east (a full lean: the
    mapping's 1 m), held it steps again after ``repeat`` s, a half lean forward steps 0.5 m
    north; button A makes a UAV hover (its queue shows it), B cancels it; Start quits."""
    clock = Clock()
    with Client(server.address, timeout=5.0) as client:
        start = client.robot("op1")["pose"]
        walker = Gamepad(client, "op1", virtual_pad, load_mapping(None), clock=clock)
        sdl2.SDL_JoystickSetVirtualAxis(virtual_pad, 0, 32767)  # full right
        assert walker.poll() and walker.last == "stick east 1 m"
        clock.now = 0.2
        assert walker.poll() and walker.last == "stick east 1 m"  # held: not again yet
        client.step(until=10.0)
        clock.now = 0.6
        walker.poll()  # held past `repeat`: one more step east
        client.step(until=20.0)
        sdl2.SDL_JoystickSetVirtualAxis(virtual_pad, 0, 0)
        sdl2.SDL_JoystickSetVirtualAxis(virtual_pad, 1, -16384)  # half forward
        clock.now = 1.2
        walker.poll()
        assert walker.last == "stick north 0.5 m"
        client.step(until=30.0)
        end = client.robot("op1")["pose"]
        assert end[0] - start[0] == pytest.approx(2.0, abs=0.05)
        assert end[1] - start[1] == pytest.approx(0.5, abs=0.05)

        sdl2.SDL_JoystickSetVirtualAxis(virtual_pad, 1, 0)
        flyer = Gamepad(client, "uav1", virtual_pad, load_mapping(None), clock=clock)
        sdl2.SDL_JoystickSetVirtualButton(virtual_pad, 0, 1)  # A: hover 5 s
        assert flyer.poll() and flyer.last == "hover"
        client.step(until=31.0)
        current = client.queue("uav1")["current"]
        assert current is not None and current["action"] == "hover"
        assert current["params"] == {"duration": 5}
        sdl2.SDL_JoystickSetVirtualButton(virtual_pad, 0, 0)
        sdl2.SDL_JoystickSetVirtualButton(virtual_pad, 1, 1)  # B: stop
        flyer.poll()
        sdl2.SDL_JoystickSetVirtualButton(virtual_pad, 1, 0)
        client.step(until=31.5)
        assert flyer.last == "stop" and client.queue("uav1")["current"] is None
        sdl2.SDL_JoystickSetVirtualButton(virtual_pad, 7, 1)  # Start: quit
        assert not flyer.poll()


def test_without_a_controller_teleop_says_so_in_one_line(server: Background) -> None:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(["teleop", "op1", "--gamepad", "--connect", server.address])
    assert code == 2
    assert err.getvalue().strip() == \
        "error: --gamepad: no game controller is attached (SDL sees none)"


def test_a_mapping_with_a_bad_key_is_refused_with_its_line(server: Background,
                                                          tmp_path: Path) -> None:
    mapping = tmp_path / "pad.yaml"
    mapping.write_text("step: 1.0\nbuttons:\n  0: {acton: hover}\n", encoding="utf-8")
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(["teleop", "op1", "--gamepad", "--mapping", str(mapping),
                     "--connect", server.address])
    assert code == 2
    assert err.getvalue().strip().startswith(f"error: {mapping}:3: buttons.0.acton")
