"""``astralis teleop ROBOT --gamepad``: drive a robot with a game controller.

The controller is read through SDL (PySDL2 and its SDL2 binaries: the ``gamepad`` extra).
It sends the requests the keyboard sends, and a few more: the left stick steps the robot
north, south, east or west (the way it leans most; a step as long as it leans, up to
``step`` metres, repeated while it is held), and each button runs what the mapping gives
it: ``stop`` (cancel the robot's tasks), ``quit``, or an action (``hover``, ``take_off``,
``land``, ... with its parameters), which preempts what the robot is doing. The mapping is
a small YAML file (``--mapping``; the default is ``astralis_des/data/gamepad.yaml``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from astralis_des.api.protocol import MAX_TELEOP_STEP, ApiError
from astralis_des.errors import InputError

DEFAULT_MAPPING = Path(__file__).resolve().parents[1] / "data" / "gamepad.yaml"
POLL = 0.05  # wall s between reads of the controller
FULL = 32767.0  # an SDL axis at full lean


class Button(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    stop: bool = Field(False, description="cancel the robot's running and queued tasks")
    quit: bool = Field(False, description="end the teleop session")
    action: str | None = Field(None, description="an action to run now (preempting)")
    params: dict[str, Any] = Field(default_factory=dict, description="the action's parameters")


class Mapping(BaseModel):
    """Which axes step the robot and what each button does."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    x_axis: int = Field(0, ge=0, description="SDL axis: lean right steps east")
    y_axis: int = Field(1, ge=0, description="SDL axis: lean forward (negative) steps north")
    deadzone: float = Field(0.3, ge=0.0, lt=1.0, description="share of a full lean ignored")
    step: float = Field(1.0, gt=0.0, le=MAX_TELEOP_STEP, description="m a full lean steps")
    repeat: float = Field(0.5, gt=0.0, description="wall s between steps while held")
    buttons: dict[int, Button] = Field(default_factory=dict, description="SDL button number")


def load_mapping(path: Path | None) -> Mapping:
    """A mapping file (one-line errors naming file, line and key, as a mission's)."""
    from astralis_des.validation import validate
    from astralis_des.yamlio import load_yaml

    doc = load_yaml(path or DEFAULT_MAPPING)
    return validate(Mapping, doc)


def open_pad(index: int = 0) -> Any:
    """SDL started for joysticks, and controller ``index`` opened; a one-line error when SDL
    is not installed or no controller is attached."""
    try:
        import sdl2
    except ImportError as exc:
        raise InputError("the gamepad needs SDL: pip install 'astralis-des[gamepad]' "
                         f"({exc.name} is not installed)", key="--gamepad") from None
    if sdl2.SDL_WasInit(sdl2.SDL_INIT_JOYSTICK) == 0 and \
            sdl2.SDL_Init(sdl2.SDL_INIT_JOYSTICK) != 0:
        raise InputError(f"SDL could not start: {sdl2.SDL_GetError().decode()}", key="--gamepad")
    if sdl2.SDL_NumJoysticks() <= index:
        raise InputError("no game controller is attached (SDL sees none)", key="--gamepad")
    pad = sdl2.SDL_JoystickOpen(index)
    if not pad:
        raise InputError(f"game controller {index} could not be opened: "
                         f"{sdl2.SDL_GetError().decode()}", key="--gamepad")
    return pad


@dataclass
class Gamepad:
    """One robot driven from an open SDL joystick: ``poll()`` reads it and sends requests."""

    client: Any
    robot: str
    pad: Any
    mapping: Mapping
    clock: Callable[[], float] = time.monotonic
    last: str = "ready"
    _held: dict[int, bool] = field(default_factory=dict)
    _next_step: float = 0.0

    def poll(self) -> bool:
        """Read the controller once and act on it; false once a ``quit`` button is pressed."""
        import sdl2

        sdl2.SDL_JoystickUpdate()
        for number, button in sorted(self.mapping.buttons.items()):
            down = bool(sdl2.SDL_JoystickGetButton(self.pad, number))
            pressed = down and not self._held.get(number, False)
            self._held[number] = down
            if pressed:
                if button.quit:
                    return False
                self._press(button)
        self._stick(sdl2.SDL_JoystickGetAxis(self.pad, self.mapping.x_axis) / FULL,
                    sdl2.SDL_JoystickGetAxis(self.pad, self.mapping.y_axis) / FULL)
        return True

    def _stick(self, x: float, y: float) -> None:
        lean = max(abs(x), abs(y))
        if lean <= self.mapping.deadzone:
            self._next_step = 0.0  # let go: the next lean steps at once
            return
        now = self.clock()
        if now < self._next_step:
            return
        self._next_step = now + self.mapping.repeat
        direction = ("east" if x > 0 else "west") if abs(x) >= abs(y) else \
            ("north" if y < 0 else "south")
        distance = round(min(lean, 1.0) * self.mapping.step, 3)
        try:
            self.client.teleop(self.robot, direction, distance=distance)
            self.last = f"stick {direction} {distance:g} m"
        except ApiError as exc:
            self.last = f"stick {direction}: {exc.code}: {exc.message}"

    def _press(self, button: Button) -> None:
        try:
            if button.stop:
                self.client.cancel(self.robot)
                self.last = "stop"
            elif button.action is not None:
                self.client.preempt(self.robot, button.action,
                                    params=button.params or None)
                self.last = f"{button.action}"
        except ApiError as exc:
            self.last = f"{button.action or 'stop'}: {exc.code}: {exc.message}"


def drive_pad(pad: Gamepad, show: Callable[[str], None], line: Callable[[], str]) -> None:
    """Poll until a quit button; the status line after each change."""
    shown = ""
    while pad.poll():
        text = f"{line()} | {pad.last}"
        if text != shown:
            show(text)
            shown = text
        time.sleep(POLL)
