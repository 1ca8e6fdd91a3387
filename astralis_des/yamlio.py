"""Safe YAML reading that remembers where every key stands and rejects duplicate keys."""

from __future__ import annotations

import contextlib
import gc
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import Any, BinaryIO

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
            mode = where.stat().st_mode
        except FileNotFoundError:
            raise self.error(path, f"no such {what}: "
                             f"{where if len(str(where)) <= 300 else shown}") from None
        except (OSError, ValueError) as exc:  # ENAMETOOLONG; "embedded null byte"
            reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            raise self.error(path, f"cannot use '{shown}' as a {what}: {reason}") from None
        if not stat.S_ISREG(mode):
            raise self.error(path, f"cannot use '{shown}' as a {what}: it is "
                             f"{_special(mode)}, not a regular file")
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


MAX_VALUES = 2_000_000  # a file of more keys, items and scalars than this is refused (a
# 100,000-event timeline holds about a million)
MAX_ALIASED = 200_000  # values that aliases may add to a file, once expanded
MAX_DEPTH = 64  # lists and mappings nested deeper than this are refused (no file needs it)
MAX_BYTES = 50_000_000  # a larger file is refused before it is read (a 100,000-event timeline
# is 6 MB; a world of 10,000 rooms 0.1 MB)
_PLAIN_TAGS = {"tag:yaml.org,2002:map", "tag:yaml.org,2002:seq", "tag:yaml.org,2002:omap"}
_MERGE = "tag:yaml.org,2002:merge"
_LOADER = yaml.CSafeLoader if yaml.__with_libyaml__ else yaml.SafeLoader  # libyaml: 40x faster
_SCALARS = yaml.SafeLoader("")  # resolves and constructs scalars, never a document


class _Builder:
    """Turns the parser's events into plain data in one pass, recording the line of every key
    path: no node graph is kept, and the limits are met as the events come.

    Aliases are followed, with a budget on the values they add and a refusal of recursive
    ones; tags other than YAML's own are refused, as are non-scalar keys, nesting deeper
    than ``MAX_DEPTH`` and more than ``MAX_VALUES`` values.
    """

    def __init__(self, text: str, file: Path) -> None:
        self.file = file
        self.lines: dict[KeyPath, int] = {}
        self.values = 0  # keys, items and scalars read
        self.expanded = 0  # values the data holds once every alias is followed
        self.aliased = 0  # of which aliases added
        self.top: str | None = None  # the top-level key being read, for errors
        self._events = yaml.parse(text, Loader=_LOADER)
        self._anchors: dict[str, tuple[Any, int, int]] = {}  # name -> value, size, line
        self._open: dict[str, int] = {}  # anchors of the collections being built -> line
        self._scalars: dict[tuple[str | None, str, Any], Any] = {}  # (tag, text, implicit)

    def document(self) -> Any:
        """The one document's data; ``None`` with no document at all (an empty file)."""
        self._next()  # the stream's start
        event = self._next()
        if isinstance(event, yaml.StreamEndEvent):
            return None
        root = self._next()
        self.lines[()] = root.start_mark.line + 1
        data = self._node(root, (), 0)
        self._next()  # the document's end
        event = self._next()
        if not isinstance(event, yaml.StreamEndEvent):
            raise self._fail(event, "YAML syntax error: a second document (a file holds one)",
                             ())
        return data

    def _next(self) -> Any:
        try:
            return next(self._events)
        except yaml.MarkedYAMLError as exc:
            if "maximum nesting depth" not in str(exc.problem):  # libyaml's own, at 1,000
                raise
            line = exc.problem_mark.line + 1 if exc.problem_mark else None
            raise InputError(f"nested more than {MAX_DEPTH} levels deep", file=self.file,
                             line=line, key=self.top) from None

    def _fail(self, event: Any, message: str, path: KeyPath) -> InputError:
        return InputError(message, file=self.file, line=event.start_mark.line + 1,
                          key=format_path(path) or None)

    def _node(self, event: Any, path: KeyPath, depth: int) -> Any:
        if isinstance(event, yaml.AliasEvent):
            return self._alias(event, path)
        self.values += 1
        if self.values > MAX_VALUES:
            raise InputError(f"the file holds more than {MAX_VALUES:,} values (keys, items "
                             "and scalars)", file=self.file, line=event.start_mark.line + 1,
                             key=self.top)
        if event.anchor is not None:
            self._claim(event, path)
        before = self.expanded
        self.expanded += 1
        if isinstance(event, yaml.ScalarEvent):
            value = self._scalar(event, path)
        else:
            value = self._collection(event, path, depth + 1)
        if event.anchor is not None:
            self._anchors[event.anchor] = (value, self.expanded - before,
                                           event.start_mark.line + 1)
        return value

    def _collection(self, event: Any, path: KeyPath, depth: int) -> Any:
        if depth > MAX_DEPTH:
            raise InputError(f"nested more than {MAX_DEPTH} levels deep", file=self.file,
                             line=event.start_mark.line + 1, key=self.top)
        default = "tag:yaml.org,2002:seq" if isinstance(event, yaml.SequenceStartEvent) \
            else "tag:yaml.org,2002:map"
        tag = default if event.tag in (None, "!") else event.tag
        if tag not in _PLAIN_TAGS:
            raise self._fail(event, f"tag '{tag}' is not allowed", path)
        if event.anchor is not None:
            self._open[event.anchor] = event.start_mark.line + 1
        try:
            if isinstance(event, yaml.SequenceStartEvent):
                return self._sequence(path, depth)
            return self._mapping(path, depth)
        finally:
            if event.anchor is not None:
                del self._open[event.anchor]

    def _claim(self, event: Any, path: KeyPath) -> None:
        """An anchor is defined once (PyYAML's composer refuses a second one too)."""
        first = self._anchors[event.anchor][2] if event.anchor in self._anchors \
            else self._open.get(event.anchor)
        if first is not None:
            raise self._fail(event, f"YAML syntax error: the anchor '&{event.anchor}' is "
                             f"defined twice (first at line {first})", path)

    def _alias(self, event: Any, path: KeyPath) -> Any:
        if event.anchor in self._open:
            raise InputError("a recursive alias refers to itself", file=self.file,
                             line=self._open[event.anchor], key=format_path(path) or None)
        if event.anchor not in self._anchors:
            raise self._fail(event, f"YAML syntax error: found undefined alias "
                             f"'*{event.anchor}'", path)
        value, size, _ = self._anchors[event.anchor]
        self.expanded += size
        self.aliased += size
        if self.aliased > MAX_ALIASED:
            raise self._fail(event, f"aliases expand the file by more than {MAX_ALIASED:,} "
                             "values (nested too deep?)", path)
        return value

    def _sequence(self, path: KeyPath, depth: int) -> list[Any]:
        value: list[Any] = []
        while not isinstance(event := self._next(), yaml.SequenceEndEvent):
            child = (*path, len(value))
            self.lines[child] = event.start_mark.line + 1
            value.append(self._node(event, child, depth))
        return value

    def _mapping(self, path: KeyPath, depth: int) -> dict[str, Any]:
        result: dict[str, Any] = {}
        merged: dict[str, Any] = {}
        while not isinstance(key_event := self._next(), yaml.MappingEndEvent):
            if isinstance(key_event, yaml.CollectionStartEvent):
                raise self._fail(key_event, "a mapping key must be a plain value", path)
            if isinstance(key_event, yaml.AliasEvent):
                key_value = self._alias(key_event, path)
                if isinstance(key_value, dict | list):
                    raise self._fail(key_event, "a mapping key must be a plain value", path)
            elif (key_event.value == "<<" or key_event.tag not in (None, "!")) \
                    and self._tag(key_event) == _MERGE:
                self.values += 1
                value_event = self._next()
                value = self._node(value_event, path, depth)
                for source in value if isinstance(value, list) else [value]:
                    if not isinstance(source, dict):
                        raise self._fail(value_event, "'<<' merges mappings only", path)
                    merged.update({k: v for k, v in source.items() if k not in merged})
                continue
            else:
                key_value = self._node(key_event, path, depth)
            key = str(key_value)
            child = (*path, key)
            if key in result:
                raise InputError(f"duplicate key '{key}' (first at line {self.lines[child]})",
                                 file=self.file, line=key_event.start_mark.line + 1,
                                 key=format_path(child))
            self.lines[child] = key_event.start_mark.line + 1
            if not path:
                self.top = key
            result[key] = self._node(self._next(), child, depth)
        for key, value in merged.items():
            result.setdefault(key, value)
        return result

    @staticmethod
    def _tag(event: Any) -> str:
        if event.tag not in (None, "!"):
            return str(event.tag)
        return str(_SCALARS.resolve(yaml.ScalarNode, event.value, event.implicit))

    def _scalar(self, event: Any, path: KeyPath) -> Any:
        """The scalar's value, as PyYAML's safe loader makes it (each kind of text once)."""
        memo = (event.tag, event.value, event.implicit)
        if memo in self._scalars:
            return self._scalars[memo]
        node = yaml.ScalarNode(self._tag(event), event.value, event.start_mark,
                               event.end_mark, event.style)
        try:
            value = _SCALARS.construct_object(node, deep=True)
        except yaml.constructor.ConstructorError as exc:
            raise self._fail(event, f"YAML error: {exc.problem}", path) from None
        finally:
            _SCALARS.constructed_objects.clear()  # it keeps every node it made, else
        self._scalars[memo] = value
        return value


def _special(mode: int) -> str:
    """What a file that is not a regular one is, for an error."""
    for test, what in ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return what
    return "a special file"


def read_bytes(file: str | Path) -> bytes:
    """The bytes of a regular file of at most ``MAX_BYTES``; anything else (a folder, a FIFO,
    ``/dev/zero``, a larger file) is an :class:`InputError` before a byte is read: nothing
    blocks, nothing fills the memory."""
    path = Path(file)
    try:
        info = path.stat()
        if not stat.S_ISREG(info.st_mode):
            raise InputError(f"cannot read {_special(info.st_mode)}, only a regular file",
                             file=path)
        if info.st_size > MAX_BYTES:
            raise InputError(_too_big(info.st_size), file=path)
        with path.open("rb") as f:
            data = _read_at_most(f, MAX_BYTES + 1)  # it may have grown since
    except FileNotFoundError:
        raise InputError("no such file", file=path) from None
    except OSError as exc:
        raise InputError(f"cannot read file: {exc.strerror or exc}", file=path) from None
    if len(data) > MAX_BYTES:
        raise InputError(_too_big(len(data)), file=path)
    return data


def _read_at_most(f: BinaryIO, limit: int) -> bytes:
    chunks: list[bytes] = []
    size = 0
    while size < limit:
        chunk = f.read(min(1 << 20, limit - size))
        if not chunk:
            break
        chunks.append(chunk)
        size += len(chunk)
    return b"".join(chunks)


def _too_big(size: int) -> str:
    return (f"cannot read a file of {size:,} bytes: a YAML file may hold at most "
            f"{MAX_BYTES:,} ({MAX_BYTES // 1_000_000} MB)")


@contextlib.contextmanager
def _no_gc() -> Iterator[None]:
    """The cyclic garbage collector paused: reading a large file makes a million objects that
    all stay alive, and each collection would walk them (two thirds of the time of a
    100,000-event timeline)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def load_yaml(file: str | Path) -> LocatedYaml:
    """Read ``file`` safely; an unreadable file or bad syntax is an :class:`InputError`."""
    path = Path(file)
    try:
        text = read_bytes(path).decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"cannot read file: {exc}", file=path) from None
    with _no_gc():
        return _load(text, path)


def _load(text: str, path: Path) -> LocatedYaml:
    builder = _Builder(text, path)
    try:
        data = builder.document()
    except yaml.MarkedYAMLError as exc:
        # An unclosed bracket or quote shows up lines later, often at the end of the file;
        # the line where it was opened (the context) is the one to fix.
        opened = bool(exc.context) and any(w in str(exc.context) for w in ("flow", "quoted",
                                                                             "simple key"))
        mark = exc.context_mark if opened and exc.context_mark else exc.problem_mark
        # libyaml places an error at the end of a file on the line after the last
        line = min(mark.line + 1, len(text.splitlines()) or 1) if mark is not None else None
        what = exc.problem or str(exc)
        if opened:
            what += f" ({exc.context} that starts here)"
        raise InputError(f"YAML syntax error: {what}", file=path, line=line) from None
    except yaml.YAMLError as exc:
        raise InputError(f"YAML error: {exc}", file=path) from None
    if () not in builder.lines:
        raise InputError("the file is empty", file=path)
    return LocatedYaml(data, builder.lines, path)
