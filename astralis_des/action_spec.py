"""An action is one record: its function, the kinds that run it, its parameters (a pydantic
model with defaults and ranges), whether it needs a room, whether it searches one, its
expected seconds per m^2, its Table IV cells and its words in the chat.

Everything else (the checks of a mission's and the API's params, the Table IV rule, the
planners' durations, the environments' searches, the chat's verbs, ``docs/missions.md``) is
derived from the registered records (:data:`astralis_des.plugins.ACTIONS`, keyed by
``(kind, name)``: one record may serve several kinds, and two kinds may each have an action of
the same name with its own record and schema).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated, Any

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, ValidationError


def _not_bool(value: Any) -> Any:
    if isinstance(value, bool):  # YAML's yes/no are not numbers
        raise ValueError("a bool")
    return value


# A finite number; a string that reads as one will do (the chat's ``spacing=2``).
Number = Annotated[float, BeforeValidator(_not_bool), Field(allow_inf_nan=False)]


class ActionParams(BaseModel):
    """An action's parameters: a field each, with its default and range; no others."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class AnyParams(ActionParams):
    """A plug-in's action registered as a bare function: it takes whatever it is given."""

    model_config = ConfigDict(extra="allow", frozen=True)


@dataclass(frozen=True)
class Verb:
    """A chat word for an action: ``<robot> <word> [ROOM] [variant]``. The action is what the
    word runs with ``variant`` after it (or, the first registered, with none); ``number`` is
    the parameter a bare number in the room's place sets (``uav1 hover 30``)."""

    word: str
    help: str = ""
    variant: str | None = None
    number: str | None = None


_JSON = {"ge": "minimum", "le": "maximum", "gt": "exclusiveMinimum", "lt": "exclusiveMaximum"}
Cell = tuple[bool, bool]  # Table IV: (high risk, high messiness)


@dataclass(frozen=True)
class ActionSpec:
    """Everything about one action; registered once under ``(kind, name)`` for each kind."""

    name: str
    kinds: tuple[str, ...]
    run: Callable[..., Any]  # run(ctx, robot, task): a generator returning an ActionResult
    doc: str = ""
    params: type[ActionParams] = ActionParams
    room: bool = True  # needs a room (with ``point``: or params x and y)
    point: bool = False
    search: bool = False  # searches a room (the environments' actions)
    seconds_per_m2: float | None = None  # a planner's estimate; None: not measured
    table4: tuple[Cell, ...] = ()  # the cells of its kinds' Table IV rows it is the rule for
    verbs: tuple[Verb, ...] = ()

    def default(self, param: str) -> Any:
        return self.params.model_fields[param].default

    def check(self, params: dict[str, Any]) -> dict[str, Any]:
        """``params`` checked (numbers as floats, no defaults added); a ``ValueError`` with
        one line naming the parameter otherwise."""
        out: dict[str, Any] = {}
        for name, value in params.items():
            if value is None and name in self.params.model_fields:  # None: "not given" inside
                wrong = "literal_error" if self.choices(name) else "float_type"
                raise ValueError(self._why(name, value, {"type": wrong}))
            try:
                given = self.params.model_validate({name: value})
            except ValidationError as exc:
                raise ValueError(self._why(name, value, exc.errors()[0])) from None
            out.update(given.model_dump(exclude_unset=True))
        return out

    def _why(self, name: str, value: Any, error: Any) -> str:
        kind, ctx = error["type"], error.get("ctx") or {}
        where = f"{self.name}: {name} must be"
        if kind == "extra_forbidden":
            known = ", ".join(self.params.model_fields) or "none"
            return f"{self.name} has no parameter '{name}' (its parameters: {known})"
        if kind == "literal_error":
            return f"{where} one of {', '.join(self.choices(name))} (got {value!r})"
        if kind in ("float_parsing", "float_type"):
            return f"{where} a number (got {value!r})"
        if kind == "greater_than_equal":
            return f"{where} at least {ctx['ge']:g} (got {float(value):g})"
        if kind == "less_than_equal":
            return f"{where} at most {ctx['le']:g} (got {float(value):g})"
        return f"{where} a finite number (got {value!r})"

    def choices(self, param: str) -> tuple[str, ...]:
        schema = self.params.model_json_schema()["properties"][param]
        return tuple(schema.get("enum", ()))

    def fields(self) -> dict[str, dict[str, Any]]:
        """Each parameter's JSON Schema, ``None`` (no default: computed, or not given) left
        out of its type."""
        out = {}
        for name, node in self.params.model_json_schema().get("properties", {}).items():
            options = [n for n in node.get("anyOf", ()) if n.get("type") != "null"]
            if len(options) == 1:  # pydantic leaves the validator's names in a union's branch
                option = {_JSON.get(k, k): v for k, v in options[0].items()}
                node = {k: v for k, v in node.items() if k != "anyOf"} | option
            out[name] = node
        return out
