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

    def file_at(self, path: KeyPath, name: str, what: str = "file") -> Path:
        """The existing file that key ``path`` names (``name``, relative to this file's folder);
        else an error at that key, also for a name no file system takes (too long, a NUL)."""
        shown = name if len(name) <= 120 else f"{name[:60]}... ({len(name):,} characters)"
        try:
            where = (self.file.parent / name).resolve()
            found = where.is_file()
        except (OSError, ValueError) as exc:  # ENAMETOOLONG; "embedded null byte"
            reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            raise self.error(path, f"cannot use '{shown}' as a {what}: {reason}") from None
        if not found:
            raise self.error(path, f"no such {what}: "
                             f"{where if len(str(where)) <= 300 else shown}")
        return where

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


MAX_VALUES = 200_000  # a file that expands to more values than this is refused
_PLAIN_TAGS = {"tag:yaml.org,2002:map", "tag:yaml.org,2002:seq", "tag:yaml.org,2002:omap"}


class _Builder:
    """Turns a composed node graph into plain data, recording the line of every key path.

    Aliases are followed, with a budget on the values they expand to and a refusal of
    recursive ones; tags other than YAML's own are refused, as are non-scalar keys.
    """

    def __init__(self, file: Path) -> None:
        self.file = file
        self.lines: dict[KeyPath, int] = {}
        self.expanded = 0  # values the data holds once every alias is followed
        self._stack: set[int] = set()
        self._shared: dict[int, tuple[Any, int]] = {}  # aliased node -> its value and size

    def _fail(self, node: yaml.Node, message: str, path: KeyPath) -> InputError:
        return InputError(message, file=self.file, line=node.start_mark.line + 1,
                          key=format_path(path) or None)

    def build(self, node: yaml.Node, path: KeyPath) -> Any:
        if id(node) in self._shared:  # an alias: the value built at its anchor, shared
            value, size = self._shared[id(node)]
            self._grow(node, size, path)
            return value
        before = self.expanded
        self._grow(node, 1, path)
        if isinstance(node, yaml.ScalarNode):
            return _scalar(node, self, path)
        if node.tag not in _PLAIN_TAGS:
            raise self._fail(node, f"tag '{node.tag}' is not allowed", path)
        if id(node) in self._stack:
            raise self._fail(node, "a recursive alias refers to itself", path)
        self._stack.add(id(node))
        try:
            if isinstance(node, yaml.SequenceNode):
                value = []
                for index, item in enumerate(node.value):
                    self.lines[(*path, index)] = item.start_mark.line + 1
                    value.append(self.build(item, (*path, index)))
            else:
                value = self._mapping(node, path)
        finally:
            self._stack.discard(id(node))
        self._shared[id(node)] = (value, self.expanded - before)
        return value

    def _grow(self, node: yaml.Node, size: int, path: KeyPath) -> None:
        self.expanded += size
        if self.expanded > MAX_VALUES:
            raise self._fail(node, f"the file expands to more than {MAX_VALUES:,} values "
                             "(aliases nested too deep?)", path)

    def _mapping(self, node: yaml.Node, path: KeyPath) -> dict[str, Any]:
        result: dict[str, Any] = {}
        merged: dict[str, Any] = {}
        for key_node, value_node in node.value:
            if not isinstance(key_node, yaml.ScalarNode):
                raise self._fail(key_node, "a mapping key must be a plain value", path)
            if key_node.tag == "tag:yaml.org,2002:merge":
                sources = value_node.value if isinstance(value_node, yaml.SequenceNode) \
                    else [value_node]
                for source in sources:
                    value = self.build(source, path)
                    if not isinstance(value, dict):
                        raise self._fail(value_node, "'<<' merges mappings only", path)
                    merged.update({k: v for k, v in value.items() if k not in merged})
                continue
            key = str(_scalar(key_node, self, path))
            child = (*path, key)
            if key in result:
                raise InputError(f"duplicate key '{key}' (first at line {self.lines[child]})",
                                 file=self.file, line=key_node.start_mark.line + 1,
                                 key=format_path(child))
            self.lines[child] = key_node.start_mark.line + 1
            result[key] = self.build(value_node, child)
        for key, value in merged.items():
            result.setdefault(key, value)
        return result


_SCALAR_LOADER = yaml.SafeLoader("")


def _scalar(node: yaml.ScalarNode, builder: _Builder, path: KeyPath) -> Any:
    try:
        return _SCALAR_LOADER.construct_object(node, deep=True)
    except yaml.constructor.ConstructorError as exc:
        raise builder._fail(node, f"YAML error: {exc.problem}", path) from None


MAX_DEPTH = 64  # lists and mappings nested deeper than this are refused (no file needs it)


def _check_depth(text: str, path: Path) -> None:
    """Refuse nesting deeper than ``MAX_DEPTH``, naming the line and the top-level key, before
    the (recursive) composer meets it: the parser's events come one at a time."""
    depth, key, expect_key = 0, None, False
    for event in yaml.parse(text, Loader=yaml.SafeLoader):
        if isinstance(event, yaml.CollectionStartEvent):
            if depth == 1:
                expect_key = False
            depth += 1
            if depth == 1:
                expect_key = isinstance(event, yaml.MappingStartEvent)
            if depth > MAX_DEPTH:
                mark = event.start_mark
                raise InputError(f"nested more than {MAX_DEPTH} levels deep", file=path,
                                 line=mark.line + 1 if mark is not None else None, key=key)
        elif isinstance(event, yaml.CollectionEndEvent):
            depth -= 1
            if depth == 1:
                expect_key = True
        elif isinstance(event, yaml.ScalarEvent) and depth == 1:
            if expect_key:
                key = event.value
            expect_key = not expect_key


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
        _check_depth(text, path)
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as exc:
        # An unclosed bracket or quote shows up lines later, often at the end of the file;
        # the line where it was opened (the context) is the one to fix.
        opened = bool(exc.context) and any(w in str(exc.context) for w in ("flow", "quoted"))
        mark = exc.context_mark if opened and exc.context_mark else exc.problem_mark
        line = mark.line + 1 if mark is not None else None
        what = exc.problem or str(exc)
        if opened:
            what += f" ({exc.context} that starts here)"
        raise InputError(f"YAML syntax error: {what}", file=path, line=line) from None
    except yaml.YAMLError as exc:
        raise InputError(f"YAML error: {exc}", file=path) from None
    if root is None:
        raise InputError("the file is empty", file=path)
    builder = _Builder(path)
    builder.lines[()] = root.start_mark.line + 1
    data = builder.build(root, ())
    return LocatedYaml(data, builder.lines, path)
