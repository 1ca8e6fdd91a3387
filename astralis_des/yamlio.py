"""Safe YAML reading that remembers where every key stands and rejects duplicate keys."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from astralis_des.errors import InputError

KeyPath = tuple[str | int, ...]


class LocatedYaml:
    """A parsed YAML document with the line of each key path (1-based)."""

    def __init__(self, data: Any, lines: dict[KeyPath, int], file: Path) -> None:
        self.data = data
        self.lines = lines
        self.file = file

    def line_of(self, path: KeyPath) -> int | None:
        """The line of ``path`` or of its nearest ancestor that has one."""
        path = tuple(path)
        while path:
            if path in self.lines:
                return self.lines[path]
            path = path[:-1]
        return self.lines.get((), None)

    def error(self, path: KeyPath, message: str) -> InputError:
        return InputError(message, file=self.file, line=self.line_of(path),
                          key=format_path(path) or None)


def format_path(path: KeyPath) -> str:
    text = ""
    for part in path:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            text += f".{part}" if text else str(part)
    return text


def _construct(node: yaml.Node, path: KeyPath, lines: dict[KeyPath, int], file: Path) -> Any:
    if isinstance(node, yaml.MappingNode):
        result: dict[str, Any] = {}
        for key_node, value_node in node.value:
            key = _construct(key_node, path, {}, file)
            if not isinstance(key, str | int | float | bool):
                raise InputError("a mapping key must be a plain value", file=file,
                                 line=key_node.start_mark.line + 1, key=format_path(path))
            key = str(key)
            child = (*path, key)
            if key in result:
                raise InputError(f"duplicate key '{key}' (first at line {lines[child]})",
                                 file=file, line=key_node.start_mark.line + 1,
                                 key=format_path(child))
            lines[child] = key_node.start_mark.line + 1
            result[key] = _construct(value_node, child, lines, file)
        return result
    if isinstance(node, yaml.SequenceNode):
        items = []
        for index, item in enumerate(node.value):
            child = (*path, index)
            lines[child] = item.start_mark.line + 1
            items.append(_construct(item, child, lines, file))
        return items
    assert isinstance(node, yaml.ScalarNode)
    return _scalar(node)


_SCALAR_LOADER = yaml.SafeLoader("")


def _scalar(node: yaml.ScalarNode) -> Any:
    return _SCALAR_LOADER.construct_object(node, deep=True)


def load_yaml(file: str | Path) -> LocatedYaml:
    """Read ``file`` safely; an unreadable file or bad syntax is an :class:`InputError`."""
    path = Path(file)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError("no such file", file=path) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read file: {exc}", file=path) from None
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else None
        raise InputError(f"YAML syntax error: {exc.problem or exc}", file=path,
                         line=line) from None
    except yaml.YAMLError as exc:
        raise InputError(f"YAML error: {exc}", file=path) from None
    if root is None:
        raise InputError("the file is empty", file=path)
    lines: dict[KeyPath, int] = {(): root.start_mark.line + 1}
    try:
        data = _construct(root, (), lines, path)
    except yaml.constructor.ConstructorError as exc:
        mark = exc.problem_mark
        raise InputError(f"YAML error: {exc.problem}", file=path,
                         line=mark.line + 1 if mark else None) from None
    return LocatedYaml(data, lines, path)
