"""Pydantic validation at the edge, with errors that name the file, line and key."""

from __future__ import annotations

import re
import types
import typing
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

from astralis_des.errors import InputError, suggest
from astralis_des.yamlio import KeyPath, LocatedYaml

M = TypeVar("M", bound=BaseModel)
SHOWN = 40  # characters of a bad string value quoted in an error


def validate(model: type[M], doc: LocatedYaml, *, context: dict[str, Any] | None = None) -> M:
    """Validate ``doc.data`` as ``model``; the first error becomes an :class:`InputError`."""
    try:
        return model.model_validate(doc.data, context=context)
    except ValidationError as exc:
        raise _to_input_error(model, doc, exc) from None


def _to_input_error(model: type[BaseModel], doc: LocatedYaml, exc: ValidationError) -> InputError:
    error = _most_useful(exc.errors())
    path = _drop_union_tags(model, _file_path(doc.data, error["loc"]))
    if error["type"] == "extra_forbidden":
        key = str(path[-1])
        owner = _model_at(model, path[:-1])
        fields = list(owner.model_fields) if owner is not None else []
        return doc.error(path, f"unknown key '{key}'; {suggest(key, fields)}")
    if error["type"] == "union_tag_invalid":
        ctx = error.get("ctx", {})
        key = str(ctx.get("discriminator", "type")).strip("'\"")
        expected = re.findall(r"'([^']*)'", str(ctx.get("expected_tags", "")))
        tag = str(ctx.get("tag", ""))
        return doc.error((*path, key), f"unknown {key} '{tag}'; {suggest(tag, expected)}")
    if error["type"] == "missing":
        return doc.error(path, "this key is required")
    message = str(error["msg"])
    if message.startswith("Value error, "):
        message = message[len("Value error, "):]
    if error["type"] not in ("value_error", "assertion_error") and "input" in error:
        value = error["input"]
        if isinstance(value, str) and len(value) > SHOWN:
            message += f" (got {value[:SHOWN]!r}..., {len(value):,} characters)"
        elif isinstance(value, str | int | float | bool):
            message += f" (got {value!r})"
    return doc.error(path, message)


def _file_path(data: Any, loc: tuple[Any, ...]) -> KeyPath:
    """The error's location without the type names pydantic puts in for a scalar union's
    member (``tuple[float, float, float]``): parts the file has, or keys that are missing."""
    path: list[str | int] = []
    for part in loc:
        present = isinstance(data, dict | list) and _has(data, part)
        if present or isinstance(part, int) or "[" not in str(part):
            path.append(part)
        data = data[part] if present else None
    return tuple(path)


def _has(data: dict[Any, Any] | list[Any], part: Any) -> bool:
    if isinstance(data, dict):
        return part in data
    return isinstance(part, int) and -len(data) <= part < len(data)


def _most_useful(errors: list[Any]) -> Any:
    """Prefer an unknown-key error, then the deepest one: it points closest to the mistake."""
    unknown = [e for e in errors if e["type"] == "extra_forbidden"]
    if unknown:
        return unknown[0]
    return max(errors, key=lambda e: len(e["loc"]))


def _drop_union_tags(model: type[BaseModel], path: KeyPath) -> KeyPath:
    """Pydantic puts a union member's name in the location; the file has no such key."""
    kept: list[str | int] = []
    current: Any = model
    for part in path:
        candidates = _models_in(current)
        union = len(candidates) > 1 or (bool(candidates) and _is_union(current))
        if isinstance(part, str) and union and not any(
                part in c.model_fields for c in candidates):
            # one model beside scalars (``Range | Literal[False]``): its class name alone
            chosen = next((c for c in candidates if _is_tag(c, part) and (
                len(candidates) > 1 or part == c.__name__)), None)
            if chosen is not None:
                current = chosen
                continue
        kept.append(part)
        current = _step(current, part)
    return tuple(kept)


def _is_union(annotation: Any) -> bool:
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _is_union(typing.get_args(annotation)[0])
    return origin in (typing.Union, types.UnionType)


def _is_tag(model: type[BaseModel], part: str) -> bool:
    """Is ``part`` the name pydantic gives this union member: its class or its tag value?"""
    if part.startswith(model.__name__):
        return True
    return any(typing.get_origin(f.annotation) is typing.Literal
               and part in typing.get_args(f.annotation) for f in model.model_fields.values())


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType, typing.Annotated):
        found: list[type[BaseModel]] = []
        for arg in typing.get_args(annotation):
            found.extend(_models_in(arg))
        return found
    return []


def _step(annotation: Any, part: str | int) -> Any:
    if annotation is None:
        return None
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _step(typing.get_args(annotation)[0], part)
    if origin in (typing.Union, types.UnionType):
        for arg in typing.get_args(annotation):
            stepped = _step(arg, part)
            if stepped is not None:
                return stepped
        return None
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        field = annotation.model_fields.get(str(part))
        return field.annotation if field is not None else None
    if origin in (list, tuple) and isinstance(part, int):
        args = typing.get_args(annotation)
        return args[0] if args else None
    if origin is dict:
        args = typing.get_args(annotation)
        return args[1] if len(args) == 2 else None
    return None


def _model_at(model: type[BaseModel], path: KeyPath) -> type[BaseModel] | None:
    current: Any = model
    for part in path:
        current = _step(current, part)
    models = _models_in(current)
    return models[0] if models else None


def check_unique_ids(doc: LocatedYaml, key: str) -> None:
    """Point at the second use of an id in the list ``key``, with the line of the first."""
    items = doc.data.get(key) if isinstance(doc.data, dict) else None
    seen: dict[object, int] = {}
    for i, item in enumerate(items if isinstance(items, list) else []):
        ident = item.get("id") if isinstance(item, dict) else None
        if ident is None or not isinstance(ident, str | int):
            continue
        if ident in seen:
            first = doc.line_of((key, seen[ident], "id"))
            raise doc.error((key, i, "id"), f"id '{ident}' is used twice"
                            + (f" (first at line {first})" if first else ""))
        seen[ident] = i
