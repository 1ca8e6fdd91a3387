"""The operations a server answers, by registry: a name, its arguments (a pydantic model that
refuses unknown keys) and a function of the :class:`~astralis_des.api.service.Service`.

Queries read the mission; commands change it, and each is an event in the log (kind
``command``, ``source: api``) and so in the recording and on the state stream. New operations
plug in with ``@op("name", ArgsModel)``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from pydantic import BaseModel, ConfigDict, ValidationError

from astralis_des.api.protocol import ApiError
from astralis_des.registry import Registry

if TYPE_CHECKING:
    from astralis_des.api.session import Session

Handler = Callable[["Session", Any], dict[str, Any]]


class Args(BaseModel):
    """Arguments of an operation: no coercion ("5" is not 5), no unknown keys."""

    model_config = ConfigDict(extra="forbid", strict=True, frozen=True)


class NoArgs(Args):
    pass


@dataclass(frozen=True)
class Op:
    name: str
    fn: Handler
    args: type[Args]
    command: bool  # changes the mission: refused once it has ended; retries are not re-run
    help: str

    def parse(self, request: dict[str, Any]) -> Args:
        given = {k: v for k, v in request.items() if k not in ("op", "id")}
        try:
            return self.args.model_validate(given)
        except ValidationError as exc:
            raise ApiError("bad_args", f"{self.name}: {explain(exc)}") from None

    def usage(self) -> str:
        fields = self.args.model_fields
        parts = [name if not f.is_required() else f"{name}!" for name, f in fields.items()]
        return f"{self.name}({', '.join(parts)})"


OPS: Registry[str, Op] = Registry(
    "op", plugins=("astralis_des.api.commands", "astralis_des.api.queries"))


def op(name: str, args: type[Args] = NoArgs, *,
       command: bool = False) -> Callable[[Handler], Handler]:
    def add(fn: Handler) -> Handler:
        first = (fn.__doc__ or "").strip().split("\n\n")[0]  # the first paragraph
        OPS.register(name)(Op(name, fn, args, command, " ".join(first.split())))
        return fn

    return add


def explain(exc: ValidationError) -> str:
    """The first problem of a validation error, in one line a person can act on."""
    err = exc.errors()[0]
    where = ".".join(str(p) for p in err["loc"])
    if err["type"] == "extra_forbidden":
        return f"unknown argument '{where}'"
    if err["type"] == "missing":
        return f"'{where}' is required"
    return f"{where}: {err['msg']}" if where else err["msg"]
